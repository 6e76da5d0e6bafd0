// Which leg the planners work on: the same rule as the controller's guidance
// (nearest leg at the start, the earliest of equally near ones, next leg
// inside the capture radius or once past the waypoint), and the
// controller's word moves them on.

#include <gtest/gtest.h>

#include "ofn/common/leg_tracker.hpp"

namespace ofn {
namespace {

constexpr int kPlan = 7;

std::vector<Waypoint> dogleg() {
  return {{Vec3(0, 0, -30), 5.0}, {Vec3(100, 0, -30), 5.0}, {Vec3(100, 100, -30), 5.0}};
}

TEST(LegTracker, StartsOnTheNearestLeg) {
  LegTracker t;
  t.set_plan(kPlan, dogleg(), Vec3(10, 1, -30));
  auto leg = t.update(Vec3(10, 1, -30));
  ASSERT_TRUE(leg);
  EXPECT_EQ(leg->index, 1);
  EXPECT_FALSE(leg->final);
  EXPECT_TRUE(leg->from.isApprox(Vec3(0, 0, -30)));
  EXPECT_DOUBLE_EQ(leg->capture_radius, 5.0);

  LegTracker late;
  late.set_plan(kPlan, dogleg(), Vec3(99, 60, -30));
  EXPECT_EQ(late.update(Vec3(99, 60, -30))->index, 2);
}

TEST(LegTracker, MovesOnInsideTheCaptureRadiusOrOncePast) {
  LegTracker t;
  t.set_plan(kPlan, dogleg(), Vec3(0, 0, -30));
  EXPECT_EQ(t.update(Vec3(90, 0, -30))->index, 1);
  EXPECT_EQ(t.update(Vec3(96, 0, -30))->index, 2);  // within 5 m of waypoint 1

  LegTracker wide;
  wide.set_plan(kPlan, dogleg(), Vec3(0, 0, -30));
  // 20 m off to the side but past the waypoint along the leg: passed.
  const auto leg = wide.update(Vec3(101, -20, -30));
  EXPECT_EQ(leg->index, 2);
  EXPECT_TRUE(leg->final);
  EXPECT_TRUE(leg->from.isApprox(Vec3(100, 0, -30)));
}

TEST(LegTracker, TheLastWaypointIsNeverPassed) {
  LegTracker t;
  t.set_plan(kPlan, dogleg(), Vec3(100, 50, -30));
  EXPECT_EQ(t.update(Vec3(100, 150, -30))->index, 2);
  EXPECT_EQ(t.update(Vec3(100, 100, -30))->index, 2);
}

/// Out to x = 200 m and back over the same line.
std::vector<Waypoint> out_and_back() {
  return {{Vec3(0, 0, -30), 5.0}, {Vec3(200, 0, -30), 5.0}, {Vec3(0, 0, -30), 5.0}};
}

TEST(NearestLeg, OfLegsThatLieOverEachOtherTheEarliestWins) {
  // On the line both legs are equally near (to the last bits); the route
  // is flown outwards first.
  for (const double x : {0.0, 0.3, 57.1, 150.0, 199.9})
    for (const double y : {0.0, 1e-9, -0.7, 3.3}) {
      SCOPED_TRACE(x);
      SCOPED_TRACE(y);
      EXPECT_EQ(nearest_leg(out_and_back(), Vec3(x, y, -30)), 1);
    }
  // A leg nearer by more than the tie distance still wins.
  const std::vector<Waypoint> offset_return = {
      {Vec3(0, 0, -30), 5.0}, {Vec3(200, 0, -30), 5.0}, {Vec3(0, 10, -30), 5.0}};
  EXPECT_EQ(nearest_leg(offset_return, Vec3(100, 6, -30)), 2);
  EXPECT_EQ(nearest_leg(offset_return, Vec3(100, 2, -30)), 1);
  EXPECT_EQ(nearest_leg({}, Vec3::Zero()), -1);
  EXPECT_EQ(nearest_leg({{Vec3(5, 0, 0), 1.0}}, Vec3::Zero()), 0);
}

TEST(LegTracker, OnTheWaypointBetweenTwoLegsTheLaterIsFlown) {
  // Both legs touch waypoint 1: the earlier is picked, and the capture
  // rule moves on at once.
  LegTracker t;
  t.set_plan(kPlan, dogleg(), Vec3(100, 0, -30));
  EXPECT_EQ(t.update(Vec3(100, 0, -30))->index, 2);
}

TEST(LegTracker, AnOutAndBackRouteIsFlownOutFirstAndThenBack) {
  LegTracker t;
  t.set_plan(kPlan, out_and_back(), Vec3(0.2, -0.1, -30));
  EXPECT_EQ(t.update(Vec3(0.2, -0.1, -30))->index, 1);
  EXPECT_EQ(t.update(Vec3(120, 0, -30))->index, 1);
  EXPECT_EQ(t.update(Vec3(197, 0, -30))->index, 2);  // captured
  const auto back = t.update(Vec3(120, 0, -30));
  EXPECT_EQ(back->index, 2);
  EXPECT_TRUE(back->final);
  EXPECT_TRUE(back->from.isApprox(Vec3(200, 0, -30)));
}

TEST(LegTracker, TheControllersLegMovesItOnButNeverBack) {
  LegTracker t;
  EXPECT_FALSE(t.follow(kPlan, 2));  // no plan yet
  t.set_plan(kPlan, out_and_back(), Vec3(120, 0, -30));
  ASSERT_EQ(t.update(Vec3(120, 0, -30))->index, 1);
  // A planner picked up on the way back cannot tell the legs apart; the
  // controller can.
  EXPECT_FALSE(t.follow(kPlan + 1, 2));  // another plan's word
  EXPECT_FALSE(t.follow(kPlan, 3));      // no such waypoint
  EXPECT_FALSE(t.follow(kPlan, -1));
  EXPECT_EQ(t.update(Vec3(120, 0, -30))->index, 1);
  EXPECT_TRUE(t.follow(kPlan, 2));
  EXPECT_EQ(t.update(Vec3(120, 0, -30))->index, 2);
  // A controller behind (its guidance waits while a plan is flown) does
  // not take the planner back.
  EXPECT_FALSE(t.follow(kPlan, 1));
  EXPECT_FALSE(t.follow(kPlan, 2));
  EXPECT_EQ(t.update(Vec3(120, 0, -30))->index, 2);
  // A new plan forgets the old plan's word.
  t.clear();
  t.set_plan(kPlan + 1, out_and_back(), Vec3(120, 0, -30));
  EXPECT_EQ(t.update(Vec3(120, 0, -30))->index, 1);
  EXPECT_FALSE(t.follow(kPlan, 2));
  EXPECT_EQ(t.update(Vec3(120, 0, -30))->index, 1);
}

TEST(LegTracker, NoPlanNoLeg) {
  LegTracker t;
  EXPECT_FALSE(t.update(Vec3::Zero()));
  t.set_plan(kPlan, {}, Vec3::Zero());
  EXPECT_FALSE(t.has_plan());
  t.set_plan(kPlan, {{Vec3(50, 0, -10), 2.0}}, Vec3(0, 0, -10));
  const auto leg = t.update(Vec3(1, 0, -10));
  ASSERT_TRUE(leg);
  EXPECT_TRUE(leg->final);
  EXPECT_TRUE(leg->from.isApprox(Vec3(0, 0, -10)));  // where the plan was picked up
}

}  // namespace
}  // namespace ofn
