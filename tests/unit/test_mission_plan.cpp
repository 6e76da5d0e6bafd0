// Which leg the planners work on: the same rule as the controller's guidance
// (nearest leg at the start, next leg inside the capture radius or once past
// the waypoint).

#include <gtest/gtest.h>

#include "ofn/common/mission_plan.hpp"

namespace ofn {
namespace {

std::vector<Waypoint> dogleg() {
  return {{Vec3(0, 0, -30), 5.0}, {Vec3(100, 0, -30), 5.0}, {Vec3(100, 100, -30), 5.0}};
}

TEST(LegTracker, StartsOnTheNearestLeg) {
  LegTracker t;
  t.set_plan(dogleg(), Vec3(10, 1, -30));
  auto leg = t.update(Vec3(10, 1, -30));
  ASSERT_TRUE(leg);
  EXPECT_EQ(leg->index, 1);
  EXPECT_FALSE(leg->final);
  EXPECT_TRUE(leg->from.isApprox(Vec3(0, 0, -30)));

  LegTracker late;
  late.set_plan(dogleg(), Vec3(99, 60, -30));
  EXPECT_EQ(late.update(Vec3(99, 60, -30))->index, 2);
}

TEST(LegTracker, MovesOnInsideTheCaptureRadiusOrOncePast) {
  LegTracker t;
  t.set_plan(dogleg(), Vec3(0, 0, -30));
  EXPECT_EQ(t.update(Vec3(90, 0, -30))->index, 1);
  EXPECT_EQ(t.update(Vec3(96, 0, -30))->index, 2);  // within 5 m of waypoint 1

  LegTracker wide;
  wide.set_plan(dogleg(), Vec3(0, 0, -30));
  // 20 m off to the side but past the waypoint along the leg: passed.
  const auto leg = wide.update(Vec3(101, -20, -30));
  EXPECT_EQ(leg->index, 2);
  EXPECT_TRUE(leg->final);
  EXPECT_TRUE(leg->from.isApprox(Vec3(100, 0, -30)));
}

TEST(LegTracker, TheLastWaypointIsNeverPassed) {
  LegTracker t;
  t.set_plan(dogleg(), Vec3(100, 50, -30));
  EXPECT_EQ(t.update(Vec3(100, 150, -30))->index, 2);
  EXPECT_EQ(t.update(Vec3(100, 100, -30))->index, 2);
}

TEST(LegTracker, NoPlanNoLeg) {
  LegTracker t;
  EXPECT_FALSE(t.update(Vec3::Zero()));
  t.set_plan({}, Vec3::Zero());
  EXPECT_FALSE(t.has_plan());
  t.set_plan({{Vec3(50, 0, -10), 2.0}}, Vec3(0, 0, -10));
  const auto leg = t.update(Vec3(1, 0, -10));
  ASSERT_TRUE(leg);
  EXPECT_TRUE(leg->final);
  EXPECT_TRUE(leg->from.isApprox(Vec3(0, 0, -10)));  // where the plan was picked up
}

}  // namespace
}  // namespace ofn
