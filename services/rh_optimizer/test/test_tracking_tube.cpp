#include "ofn/rh_optimizer/tracking_tube.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace ofn::rh {
namespace {

constexpr double kPeriod = 0.02;  // s, CONTROL_STATUS at 50 Hz

TEST(TrackingTube, CalmErrorsBelowTheOnsetWidenNothing) {
  TrackingTube tube;
  EXPECT_EQ(tube.extra_clearance(), 0.0);  // nothing heard yet
  for (int k = 0; k < 1000; ++k) tube.add(k * kPeriod, Vec3(0.2 * std::sin(0.1 * k), 0.1, -0.05));
  EXPECT_GT(tube.largest_error(), 0.2);
  EXPECT_EQ(tube.extra_clearance(), 0.0);
}

TEST(TrackingTube, AGustWidensByTheLargestErrorLessTheOnsetForTheWindow) {
  TrackingTubeSettings s;
  TrackingTube tube(s);
  double t = 0;
  for (int k = 0; k < 100; ++k, t += kPeriod) tube.add(t, Vec3(0.1, 0, 0));
  // A gust: the vehicle 2 m off its plan, for a second.
  for (int k = 0; k < 50; ++k, t += kPeriod) tube.add(t, Vec3(0, 2.0 * k / 49, 0));
  EXPECT_NEAR(tube.extra_clearance(), 2.0 - s.onset, 1e-12);
  // Calm again: held for the window after the gust, then gone.
  const double gust_end = t - kPeriod;
  for (; t < gust_end + s.window - 0.1; t += kPeriod) tube.add(t, Vec3(0.1, 0, 0));
  EXPECT_NEAR(tube.extra_clearance(), 2.0 - s.onset, 1e-12);
  for (; t < gust_end + s.window + 0.1; t += kPeriod) tube.add(t, Vec3(0.1, 0, 0));
  EXPECT_EQ(tube.extra_clearance(), 0.0);
}

TEST(TrackingTube, TheWideningIsCapped) {
  TrackingTubeSettings s;
  TrackingTube tube(s);
  tube.add(0.0, Vec3(0, 0, 50.0));
  EXPECT_EQ(tube.extra_clearance(), s.max_extra);
}

TEST(TrackingTube, ASilentControllerLeavesTheTubeInPlace) {
  TrackingTube tube;
  tube.add(0.0, Vec3(2.5, 0, 0));
  // No newer sample: the tube is measured up to the newest one.
  EXPECT_NEAR(tube.extra_clearance(), 2.0, 1e-12);
}

TEST(TrackingTube, AReorderedSampleStillCounts) {
  TrackingTubeSettings s;
  TrackingTube tube(s);
  tube.add(5.0, Vec3(0.1, 0, 0));
  tube.add(4.9, Vec3(2.0, 0, 0));  // overtaken on the link
  EXPECT_NEAR(tube.extra_clearance(), 2.0 - s.onset, 1e-12);
  // Held a window from when it was heard, not lost at once.
  tube.add(5.0 + s.window - 0.5, Vec3(0.1, 0, 0));
  EXPECT_NEAR(tube.extra_clearance(), 2.0 - s.onset, 1e-12);
}

TEST(TrackingTube, BadSamplesAreIgnoredAndAClockGoingBackStartsAgain) {
  TrackingTube tube;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  tube.add(1.0, Vec3(1.5, 0, 0));
  tube.add(1.1, Vec3(nan, 0, 0));
  tube.add(nan, Vec3(9, 0, 0));
  tube.add(1.2, Vec3(std::numeric_limits<double>::infinity(), 0, 0));
  EXPECT_NEAR(tube.largest_error(), 1.5, 1e-12);
  tube.add(20.0, Vec3(0.2, 0, 0));
  tube.add(1.0, Vec3(0.1, 0, 0));  // a restarted clock
  EXPECT_NEAR(tube.largest_error(), 0.1, 1e-12);
  EXPECT_EQ(tube.extra_clearance(), 0.0);
}

TEST(TrackingTube, DisabledWidensNothing) {
  TrackingTubeSettings s;
  s.enabled = false;
  TrackingTube tube(s);
  tube.add(0.0, Vec3(3.0, 0, 0));
  EXPECT_EQ(tube.extra_clearance(), 0.0);
}

}  // namespace
}  // namespace ofn::rh
