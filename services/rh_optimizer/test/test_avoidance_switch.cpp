// When avoidance overrides nominal guidance and when it hands back, and where
// the horizon ends (paper 2.1 and Eq. 6).

#include <gtest/gtest.h>

#include <cmath>

#include "ofn/common/braking.hpp"
#include "ofn/rh_optimizer/avoidance_switch.hpp"

namespace ofn::rh {
namespace {

/// Distance to a wall: the slab north in [n0, n1], top at altitude `top`.
ClearanceQuery wall(double n0, double n1, double top) {
  return [=](const Vec3& p) {
    const double dn = std::max({n0 - p.x(), p.x() - n1, 0.0});
    const double dh = std::max(-p.z() - top, 0.0);
    mapping::DistanceSample s;
    s.distance = std::hypot(dn, dh);
    return s;
  };
}

const Leg kLeg{Vec3(0, 0, -30), Vec3(300, 0, -30)};

TEST(NominalPath, SeesAWallAheadWithinSensorRangeOnly) {
  const SwitchSettings s;
  const auto field = wall(100, 103, 40);
  // 95 m before the wall with a 60 m sensor: nothing within range.
  const NominalCheck far = check_nominal_path(field, kLeg, Vec3(5, 0, -30), 60, 6.6, s);
  EXPECT_GT(far.least_clearance, 29.0);
  EXPECT_TRUE(std::isinf(far.conflict_distance));
  // 50 m before: the leg runs into it; the conflict starts 6.6 m short of it.
  const NominalCheck near = check_nominal_path(field, kLeg, Vec3(50, 0, -30), 60, 6.6, s);
  EXPECT_NEAR(near.least_clearance, 0.0, 1e-9);
  EXPECT_NEAR(near.conflict_distance, 50 - 6.6, 1.0);
}

TEST(NominalPath, IncludesTheWayBackToTheLeg) {
  const SwitchSettings s;
  // Above the wall at 55 m altitude: the leg ahead (past the wall) is
  // clear, but rejoining it from up here dives through nothing: clear too.
  const auto field = wall(100, 103, 40);
  EXPECT_GT(check_nominal_path(field, kLeg, Vec3(120, 0, -55), 60, 6.6, s).least_clearance, 15.0);
  // Just before the wall, high: rejoining 15 m ahead cuts into its top.
  EXPECT_LT(check_nominal_path(field, kLeg, Vec3(95, 0, -45), 60, 6.6, s).least_clearance, 2.0);
}

TEST(NominalPath, NoFieldIsOpenSpace) {
  EXPECT_TRUE(
      std::isinf(check_nominal_path({}, kLeg, Vec3(50, 0, -30), 60, 6.6, {}).least_clearance));
}

TEST(CrossTrack, IsTheDistanceToTheLegLine) {
  EXPECT_NEAR(cross_track_distance(kLeg, Vec3(50, 3, -34)), 5.0, 1e-12);
}

mapping::Heightfield grid_with_wall() {
  mapping::Heightfield g;
  g.origin_north = 0;
  g.origin_east = -20;
  g.resolution = 1;
  g.rows = 200;
  g.cols = 40;
  g.top.assign(g.rows * g.cols, 0.0f);
  for (int r = 100; r < 103; ++r)
    for (int c = 0; c < g.cols; ++c) g.at(r, c) = 40.0f;
  return g;
}

TEST(TerminalX, EndsBeyondTheFarthestObstacleOrAtSensorRange) {
  const auto frame = GuidanceFrame::from_leg(kLeg.from, kLeg.to);
  const auto g = grid_with_wall();
  // Wall cells at north 100.5..102.5; 6 m beyond: 108.5.
  EXPECT_NEAR(terminal_x(frame, g, Vec3(50, 0, -30), 60, 6, 300, 20), 108.5, 1e-9);
  // Out of sensor range: the sensor's reach.
  EXPECT_NEAR(terminal_x(frame, g, Vec3(10, 0, -30), 60, 6, 300, 20), 70.0, 1e-9);
  // Behind the vehicle: ignored; the horizon is at least min_horizon.
  EXPECT_NEAR(terminal_x(frame, g, Vec3(104, 0, -30), 60, 6, 300, 20), 164.0, 1e-9);
  EXPECT_NEAR(terminal_x(frame, g, Vec3(101, 0, -30), 60, 6, 300, 20), 121.0, 1e-9);
  // Never past the target.
  EXPECT_NEAR(terminal_x(frame, g, Vec3(10, 0, -30), 60, 6, 40, 20), 40.0, 1e-9);
}

TEST(AvoidanceSwitch, EngagesAtOnceAndHandsBackOnlyWhenClearAndNearTheLeg) {
  SwitchSettings s;
  s.handback_hold = 1.0;
  s.handback_distance = 2.0;
  AvoidanceSwitch sw(s);
  EXPECT_FALSE(sw.update(0.0, false, 0.0));
  EXPECT_TRUE(sw.update(0.1, true, 0.0));
  // Clear but 12 m above the leg: stays engaged however long.
  EXPECT_TRUE(sw.update(0.2, false, 12.0));
  EXPECT_TRUE(sw.update(5.0, false, 12.0));
  // Back near the leg, clear for longer than the hold: hands back.
  EXPECT_FALSE(sw.update(5.1, false, 1.0));
  // A conflict re-engages; a brief clear spell does not hand back.
  EXPECT_TRUE(sw.update(6.0, true, 0.0));
  EXPECT_TRUE(sw.update(6.5, false, 0.0));
  EXPECT_TRUE(sw.update(6.9, true, 0.0));
  EXPECT_TRUE(sw.update(7.5, false, 0.0));
  EXPECT_FALSE(sw.update(8.6, false, 0.0));
}

TEST(AvoidanceSwitch, StoppingAtTheLastWaypointHandsBackOnlyWhenSlow) {
  SwitchSettings s;
  s.handback_hold = 1.0;
  s.handback_stop_speed = 0.3;
  AvoidanceSwitch sw(s);
  EXPECT_TRUE(sw.update(0.0, true, 0.0));
  // Clear, on the leg, but still braking for the waypoint at 1.3 m/s:
  // waypoint guidance could not stop in the metres left.
  EXPECT_TRUE(sw.update(0.1, false, 0.0, 1.3));
  EXPECT_TRUE(sw.update(2.0, false, 0.0, 1.3));
  EXPECT_TRUE(sw.update(3.0, false, 0.0, 0.31));
  // Nearly at rest on the waypoint: hands back.
  EXPECT_FALSE(sw.update(3.5, false, 0.0, 0.2));
}

TEST(AvoidanceSwitch, AtRestInsideTheLastWaypointsRadiusItHandsBackOffTheLegToo) {
  // An out-and-back dense field: the stop at the start ended 0.37 m from
  // the leg's line (handback_distance 0.3 m), and the optimiser hovered
  // there, looking around, for 250 s. Inside the waypoint's capture radius
  // the distance from the line no longer holds the hand-back.
  SwitchSettings s;
  s.handback_hold = 1.0;
  s.handback_distance = 0.3;
  s.handback_stop_speed = 0.3;
  AvoidanceSwitch sw(s);
  EXPECT_TRUE(sw.update(0.0, true, 0.0));
  EXPECT_TRUE(sw.update(0.1, false, 0.37, 0.05));
  EXPECT_TRUE(sw.update(5.0, false, 0.37, 0.05));       // outside the radius: held
  EXPECT_TRUE(sw.update(5.1, false, 0.37, 0.5, true));  // inside, still too fast
  EXPECT_FALSE(sw.update(5.2, false, 0.37, 0.05, true));
  // Still only when clear.
  AvoidanceSwitch conflicted(s);
  EXPECT_TRUE(conflicted.update(0.0, true, 0.37, 0.05, true));
  EXPECT_TRUE(conflicted.update(5.0, true, 0.37, 0.05, true));
}

TEST(DeferFirstBrake, OnlyWhileTheConflictIsBeyondTheStopAndTheMargin) {
  // At 3 m/s braking at 0.39 m/s^2 the stop (onset and ease-out included)
  // takes about 12.3 m; with a 10 m margin a conflict 30 m on is deferred,
  // one 20 m on is braked for.
  const Vec3 cruise(3.0, 0, 0);
  const double stop = stop_from(Vec3::Zero(), cruise, 0.39).distance();
  ASSERT_GT(stop, 11.0);
  ASSERT_LT(stop, 14.0);
  EXPECT_TRUE(defer_first_brake(30.0, cruise, 0.39, 10.0));
  EXPECT_FALSE(defer_first_brake(20.0, cruise, 0.39, 10.0));
  EXPECT_FALSE(defer_first_brake(stop + 10.0, cruise, 0.39, 10.0));  // the bound itself brakes
  // From a hover only the margin counts.
  EXPECT_TRUE(defer_first_brake(10.5, Vec3::Zero(), 0.39, 10.0));
  EXPECT_FALSE(defer_first_brake(9.5, Vec3::Zero(), 0.39, 10.0));
}

}  // namespace
}  // namespace ofn::rh
