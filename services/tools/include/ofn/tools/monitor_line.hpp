#pragma once
// The progress line of the flight monitor and of the lockstep runner, in the
// scenario's unit (feet for the benchmark courses, as the summary and the
// figures are): a user watching a flight compares it with the report, so
// both speak the same unit. Pure.

#include <string>

#include "ofn/common/frames.hpp"
#include "ofn/tools/flight_analysis.hpp"

namespace ofn::report {

/// "t=  12.0 s  north  123.4 ft  east   -5.0 ft  alt   60.0 ft  speed  9.98 ft/s  mode
/// TRAJECTORY": `position` and `velocity` world NED in metres, `mode` the
/// controller's mode name ("-" before the first status).
std::string progress_line(double t, const Vec3& position, const Vec3& velocity,
                          const std::string& mode, const DisplayUnit& unit);

}  // namespace ofn::report
