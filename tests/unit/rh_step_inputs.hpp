#pragma once
// Receding-horizon steps for the planner's tests: level flight north at the
// benchmarks' speed limit along a leg from the origin to 300 m north.

#include <utility>

#include "ofn/rh_optimizer/rh_planner.hpp"

namespace ofn::rh::testing_support {

inline const Limits kBenchmarkLimits{3.048, 0.4877, 1.524, 0.0, 6.096, 60.96};  // SI
constexpr double kLegAltitude = 30.0;                                           // m

/// A step at `time` from `position` at the speed limit along the leg.
inline StepInput step_input_at(const Vec3& position, double time, ClearanceQuery clearance) {
  StepInput input;
  input.time = time;
  RhProblem& p = input.problem;
  p.frame = GuidanceFrame::from_leg(Vec3(0, 0, -kLegAltitude), Vec3(300, 0, -kLegAltitude));
  p.position = position;
  p.velocity = Vec3(kBenchmarkLimits.max_speed, 0, 0);
  p.target = Vec3(300, 0, -kLegAltitude);
  p.terminal_x = position.x() + kBenchmarkLimits.sensor_range;
  p.limits = kBenchmarkLimits;
  p.clearance = std::move(clearance);
  return input;
}

}  // namespace ofn::rh::testing_support
