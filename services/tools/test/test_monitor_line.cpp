// The flight monitor's progress line speaks the scenario's unit, as the
// summary and the figures do.

#include <gtest/gtest.h>

#include "ofn/tools/monitor_line.hpp"

namespace ofn::report {
namespace {

TEST(MonitorLine, SpeaksTheScenariosUnit) {
  const Vec3 position(30.48, -1.524, -18.288);  // 100 ft north, 5 ft west, 60 ft up
  const Vec3 velocity(3.048, 0, 0);             // 10 ft/s
  EXPECT_EQ(progress_line(12.0, position, velocity, "TRAJECTORY", {"ft", kMetresPerFoot}),
            "t=  12.0 s  north    100.0 ft  east   -5.0 ft  alt   60.0 ft  speed 10.00 ft/s  "
            "mode TRAJECTORY");
  EXPECT_EQ(progress_line(12.0, position, velocity, "-", {}),
            "t=  12.0 s  north     30.5 m  east   -1.5 m  alt   18.3 m  speed  3.05 m/s  mode -");
}

}  // namespace
}  // namespace ofn::report
