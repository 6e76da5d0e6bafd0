// Nominal waypoint guidance: speed and acceleration limits, leg switching,
// stopping at the last waypoint and picking up a plan mid-flight.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "ofn/controller/waypoint_guidance.hpp"

namespace ofn::control {
namespace {

constexpr double kGuidancePeriod = 0.01;

Limits limits(double max_speed, double max_accel, double max_vertical_speed) {
  Limits l;
  l.max_speed = max_speed;
  l.max_accel = max_accel;
  l.max_vertical_speed = max_vertical_speed;
  return l;
}

/// Flies a fake vehicle that sits exactly on the reference (position and
/// velocity copied from it each step) and records every reference.
struct PerfectFollower {
  WaypointGuidance guidance;
  Vec3 position, velocity = Vec3::Zero();
  std::vector<GuidanceReference> refs;
  std::vector<Vec3> positions;  // vehicle position passed to each update

  PerfectFollower(const std::vector<Waypoint>& wps, double cruise, const Limits& lim, Vec3 start,
                  GuidanceConfig config = {})
      : guidance(config), position(start) {
    guidance.set_mission(wps, cruise, lim, position, velocity);
  }

  /// Runs until done (or `max_seconds`); returns whether it arrived.
  bool run(double max_seconds) {
    const int steps = static_cast<int>(max_seconds / kGuidancePeriod);
    for (int i = 0; i < steps; ++i) {
      positions.push_back(position);
      const GuidanceReference r = guidance.update(position, velocity, kGuidancePeriod);
      refs.push_back(r);
      position = r.position;
      velocity = r.velocity;
      if (r.done) return true;
    }
    return false;
  }
};

TEST(WaypointGuidance, AnOutAndBackRouteIsFlownOutFirstAndThenBack) {
  // The two legs lie on one line: from the start the outward leg is flown,
  // then the way back, and the flight ends where it began.
  const std::vector<Waypoint> wps = {
      {Vec3(0, 0, -30), 5.0}, {Vec3(100, 0, -30), 5.0}, {Vec3(0, 0, -30), 5.0}};
  PerfectFollower f(wps, 10.0, limits(10, 2, 3), Vec3(1e-3, 2e-4, -30));
  ASSERT_TRUE(f.run(60));
  EXPECT_EQ(f.refs.front().active_waypoint, 1);
  double furthest = 0;
  for (const Vec3& p : f.positions) furthest = std::max(furthest, p.x());
  EXPECT_GT(furthest, 95.0);
  EXPECT_EQ(f.refs.back().active_waypoint, 2);
  EXPECT_LT((f.positions.back() - wps.back().position).norm(), 5.0);
}

TEST(WaypointGuidance, FliesThePlannersLegAndMovesOnWithIt) {
  const std::vector<Waypoint> wps = {
      {Vec3(0, 0, -30), 5.0}, {Vec3(100, 0, -30), 5.0}, {Vec3(0, 0, -30), 5.0}};
  PerfectFollower f(wps, 10.0, limits(10, 2, 3), Vec3(1e-3, 0, -30));
  EXPECT_FALSE(f.guidance.follow_leg(-1, true, f.position, f.velocity));  // the planner has none
  EXPECT_FALSE(f.guidance.follow_leg(3, true, f.position, f.velocity));   // no such waypoint
  EXPECT_FALSE(f.guidance.follow_leg(1, true, f.position, f.velocity));   // the same leg: a cap
  // Inside waypoint 1's capture radius guidance waits for the planner.
  while (f.position.x() < 97.0 && f.refs.size() < 3000) ASSERT_FALSE(f.run(kGuidancePeriod));
  ASSERT_GE(f.position.x(), 97.0);
  ASSERT_FALSE(f.run(0.1));
  EXPECT_EQ(f.refs.back().active_waypoint, 1);
  const Vec3 before = f.refs.back().position;
  // The planner moves on: on from where the reference is, no jump.
  EXPECT_TRUE(f.guidance.follow_leg(2, true, f.position, f.velocity));
  EXPECT_EQ(f.guidance.active_waypoint(), 2);
  const GuidanceReference next = f.guidance.update(f.position, f.velocity, kGuidancePeriod);
  EXPECT_EQ(next.active_waypoint, 2);
  EXPECT_LT((next.position - before).norm(), 0.2);
  EXPECT_FALSE(f.guidance.follow_leg(1, true, f.position, f.velocity));  // never back
  EXPECT_EQ(f.guidance.active_waypoint(), 2);
}

TEST(WaypointGuidance, APlannerFurtherOnWhilePlansAreFlownGivesTheTrueLeg) {
  // The planner flew the vehicle out and most of the way back; guidance,
  // idle meanwhile, takes up the way back from waypoint 1, with the
  // reference on the vehicle, rejoining the leg 15 m further on.
  const std::vector<Waypoint> wps = {
      {Vec3(0, 0, -30), 5.0}, {Vec3(100, 0, -30), 5.0}, {Vec3(0, 0, -30), 5.0}};
  WaypointGuidance g;
  g.set_mission(wps, 10.0, limits(10, 2, 3), Vec3(0, 0, -30), Vec3::Zero());
  g.update(Vec3(0, 0, -30), Vec3::Zero(), kGuidancePeriod);
  const Vec3 vehicle(30, 2, -30);
  ASSERT_TRUE(g.follow_leg(2, false, vehicle, Vec3(-3, 0, 0)));
  const GuidanceReference r = g.update(vehicle, Vec3(-3, 0, 0), kGuidancePeriod);
  EXPECT_EQ(r.active_waypoint, 2);
  EXPECT_TRUE(r.position.isApprox(vehicle, 1e-9));
  const Vec3 rejoin = (Vec3(30 - kGuidanceRejoinDistance, 0, -30) - vehicle).normalized();
  EXPECT_TRUE(r.leg_direction.isApprox(Vec3(-1, 0, 0), 1e-9));
  EXPECT_NEAR(r.velocity.dot(rejoin), 3.0 * -rejoin.x(), 1e-9);
}

TEST(WaypointGuidance, WithoutMissionGivesNoWaypoint) {
  WaypointGuidance g;
  EXPECT_FALSE(g.has_mission());
  const GuidanceReference r = g.update(Vec3(1, 2, 3), Vec3::Zero(), kGuidancePeriod);
  EXPECT_EQ(r.active_waypoint, -1);
  EXPECT_FALSE(r.done);
}

TEST(WaypointGuidance, StraightLegRespectsSpeedAndAccelerationLimitsAndStopsAtTheEnd) {
  const std::vector<Waypoint> wps = {{Vec3(0, 0, -30), 2.0}, {Vec3(100, 0, -30), 2.0}};
  const GuidanceConfig config;  // accel_fraction 0.8
  const double cruise = 3.0, max_accel = 0.5;
  PerfectFollower f(wps, cruise, limits(3.0, max_accel, 1.0), wps[0].position, config);
  ASSERT_TRUE(f.guidance.has_mission());
  const bool arrived = f.run(120.0);
  ASSERT_TRUE(arrived) << "not done after 120 s; at " << f.position.transpose();

  double max_speed = 0, max_accel_seen = 0, previous_x = -1e9;
  for (const auto& r : f.refs) {
    const double speed = r.velocity.norm();
    max_speed = std::max(max_speed, speed);
    max_accel_seen = std::max(max_accel_seen, r.acceleration.norm());
    EXPECT_LE(speed, cruise + 1e-6);
    EXPECT_LE(r.acceleration.norm(), config.accel_fraction * max_accel + 1e-9);
    // The reference stays on the leg, moves only forward and never passes the end.
    EXPECT_LE(r.position.x(), 100.0 + 1e-9);
    EXPECT_GE(r.position.x(), previous_x - 1e-12);
    EXPECT_NEAR(r.position.y(), 0.0, 1e-12);
    EXPECT_NEAR(r.position.z(), -30.0, 1e-12);
    EXPECT_EQ(r.active_waypoint, 1);
    previous_x = r.position.x();
  }
  EXPECT_GT(max_speed, 0.98 * cruise);                                 // reaches cruise
  EXPECT_GT(max_accel_seen, 0.5 * config.accel_fraction * max_accel);  // actually accelerates

  const GuidanceReference& last = f.refs.back();
  EXPECT_TRUE(last.done);
  EXPECT_LE((last.position - wps[1].position).norm(), wps[1].capture_radius);
  EXPECT_LE(last.velocity.norm(), config.stop_speed);
  // Not done any earlier than inside the capture radius.
  for (size_t i = 0; i + 1 < f.refs.size(); ++i) {
    if (f.refs[i].done) {
      EXPECT_LE((f.positions[i] - wps[1].position).norm(), wps[1].capture_radius);
    }
  }
  // A flight of 100 m at 3 m/s with gentle ramps: well under a minute.
  EXPECT_LT(f.refs.size() * kGuidancePeriod, 60.0);
  EXPECT_GT(f.refs.size() * kGuidancePeriod, 100.0 / cruise);
}

TEST(WaypointGuidance, ASpeedReserveLowersTheCruiseWithoutASpeedStep) {
  const std::vector<Waypoint> wps = {{Vec3(0, 0, -30), 2.0}, {Vec3(300, 0, -30), 2.0}};
  const GuidanceConfig config;
  const double max_speed = 3.0, max_accel = 0.5;
  PerfectFollower f(wps, max_speed, limits(max_speed, max_accel, 1.0), wps[0].position, config);
  ASSERT_FALSE(f.run(30.0));  // at cruise, mid-leg
  const double cruise = f.refs.back().velocity.norm();
  EXPECT_NEAR(cruise, config.speed_fraction * max_speed, 1e-3);

  f.guidance.set_speed_reserve(0.6);
  const size_t from = f.refs.size();
  ASSERT_FALSE(f.run(20.0));
  for (size_t i = from; i < f.refs.size(); ++i) {
    // It slows within its own acceleration limit: no step in speed.
    EXPECT_LE(f.refs[i].acceleration.norm(), config.accel_fraction * max_accel + 1e-9);
    EXPECT_LE(f.refs[i].velocity.norm(), cruise + 1e-9);
  }
  EXPECT_NEAR(f.refs.back().velocity.norm(), config.speed_fraction * max_speed - 0.6, 1e-3);

  // Released, it speeds up to the cruise again; nonsense counts as none.
  f.guidance.set_speed_reserve(std::nan(""));
  ASSERT_FALSE(f.run(20.0));
  EXPECT_NEAR(f.refs.back().velocity.norm(), cruise, 1e-3);
}

TEST(WaypointGuidance, StaysDoneAndStillAtTheLastWaypoint) {
  const std::vector<Waypoint> wps = {{Vec3(0, 0, -30), 2.0}, {Vec3(20, 0, -30), 2.0}};
  PerfectFollower f(wps, 3.0, limits(3.0, 0.5, 1.0), wps[0].position);
  ASSERT_TRUE(f.run(60.0));
  for (int i = 0; i < 500; ++i) {
    const GuidanceReference r = f.guidance.update(f.position, f.velocity, kGuidancePeriod);
    EXPECT_TRUE(r.done);
    EXPECT_LE(r.position.x(), 20.0 + 1e-9);
    EXPECT_LE(r.velocity.norm(), 1e-9);
    f.position = r.position;
    f.velocity = r.velocity;
  }
}

TEST(WaypointGuidance, SwitchesLegsInsideTheCaptureRadius) {
  const double radius = 5.0;
  const std::vector<Waypoint> wps = {
      {Vec3(0, 0, -30), radius}, {Vec3(50, 0, -30), radius}, {Vec3(50, 50, -30), radius}};
  const GuidanceConfig config;
  const double max_accel = 0.5;
  PerfectFollower f(wps, 3.0, limits(3.0, max_accel, 1.0), wps[0].position, config);
  ASSERT_TRUE(f.run(200.0)) << "at " << f.position.transpose();

  std::vector<int> sequence;
  size_t switch_index = 0;
  for (size_t i = 0; i < f.refs.size(); ++i) {
    const int active = f.refs[i].active_waypoint;
    if (sequence.empty() || sequence.back() != active) {
      sequence.push_back(active);
      if (active == 2) switch_index = i;
    }
    EXPECT_LE(f.refs[i].velocity.norm(), 3.0 + 1e-6);
    EXPECT_LE(f.refs[i].acceleration.norm(), config.accel_fraction * max_accel + 1e-9);
  }
  EXPECT_EQ(sequence, (std::vector<int>{1, 2}));
  ASSERT_GT(switch_index, 0u);
  // Switched on the first update with the vehicle inside the capture radius
  // of the corner, not before.
  const double at_switch = (f.positions[switch_index] - wps[1].position).norm();
  const double before_switch = (f.positions[switch_index - 1] - wps[1].position).norm();
  EXPECT_LE(at_switch, radius);
  EXPECT_GT(before_switch, radius);
  // The second leg heads (nearly) east, from where the reference was to the
  // last waypoint.
  EXPECT_GT(f.refs[switch_index].leg_direction.y(), 0.99)
      << f.refs[switch_index].leg_direction.transpose();
  // And it ends at the last waypoint.
  EXPECT_LE((f.refs.back().position - wps[2].position).norm(), radius);
}

TEST(WaypointGuidance, RestartMidLegPicksUpTheLegTheVehicleIsOn) {
  const std::vector<Waypoint> wps = {
      {Vec3(0, 0, -30), 5.0}, {Vec3(50, 0, -30), 5.0}, {Vec3(50, 50, -30), 5.0}};
  WaypointGuidance g;
  const Vec3 position(50.4, 24.0, -30.2);  // near the middle of leg 2
  const Vec3 velocity(0.0, 3.0, 0.0);
  g.set_mission(wps, 3.0, limits(3.0, 0.5, 1.0), position, velocity);
  const GuidanceReference r = g.update(position, velocity, kGuidancePeriod);
  EXPECT_EQ(r.active_waypoint, 2);
  // No jump: the reference starts on the vehicle, not a step ahead of it
  // nor on the leg beside it, moving at the vehicle's speed along the
  // rejoin to the leg.
  EXPECT_LT((r.position - position).norm(), 1e-9);
  EXPECT_NEAR(r.velocity.y(), 3.0, 0.05);
  EXPECT_TRUE(r.leg_direction.isApprox(Vec3::UnitY()));
  EXPECT_TRUE(r.velocity.normalized().isApprox((Vec3(50, 39, -30) - position).normalized()));
}

TEST(WaypointGuidance, ResyncStartsOnTheVehicleThenAdvances) {
  // After an avoidance hands back, the reference must restart where the
  // vehicle is: one that starts a step ahead pulls a vehicle already at the
  // speed limit past it.
  const std::vector<Waypoint> wps = {{Vec3(0, 0, -30), 2.0}, {Vec3(200, 0, -30), 2.0}};
  WaypointGuidance g;
  g.set_mission(wps, 3.0, limits(3.0, 0.5, 1.0), wps[0].position, Vec3::Zero());
  for (int i = 0; i < 100; ++i) g.update(wps[0].position, Vec3::Zero(), kGuidancePeriod);
  const Vec3 position(80, 0, -30), velocity(2.5, 0, 0);  // below the cruise
  g.resync(position, velocity);
  const GuidanceReference first = g.update(position, velocity, kGuidancePeriod);
  EXPECT_LT((first.position - position).norm(), 1e-9);
  EXPECT_NEAR(first.velocity.x(), 2.5, 1e-9);
  const GuidanceReference second =
      g.update(position + velocity * kGuidancePeriod, velocity, kGuidancePeriod);
  EXPECT_GT(second.position.x(), 80 + 2.5 * kGuidancePeriod);  // on, speeding up toward the cruise
  EXPECT_LT(second.position.x(), 80 + 3.0 * kGuidancePeriod);
}

TEST(WaypointGuidance, OffTheLegItRejoinsAlongTheCheckedSegmentWithoutAJump) {
  // A controller restarted after the vehicle drifted 2 m beside and 1 m
  // below the leg: the reference starts on the vehicle and flies the
  // straight segment to the leg kGuidanceRejoinDistance ahead (the path
  // the RH optimiser checks), then the leg, and never steps.
  const std::vector<Waypoint> wps = {{Vec3(0, 0, -30), 2.0}, {Vec3(200, 0, -30), 2.0}};
  const Vec3 start(60, -2, -29);
  PerfectFollower f(wps, 3.0, limits(3.0, 0.5, 1.0), start);
  ASSERT_TRUE(f.run(120));
  EXPECT_LT((f.refs.front().position - start).norm(), 1e-9);
  const Vec3 meet(60 + kGuidanceRejoinDistance, 0, -30);
  bool met = false;
  for (size_t i = 0; i < f.refs.size(); ++i) {
    const Vec3& p = f.refs[i].position;
    if (i > 0) {
      EXPECT_LE((p - f.refs[i - 1].position).norm(), 3.0 * kGuidancePeriod + 1e-9) << i;
    }
    if (p.x() < meet.x() - 1e-9) {
      EXPECT_LT(distance_to_segment(p, start, meet), 1e-9) << p.transpose();
    } else {
      met = true;
      EXPECT_LT(std::hypot(p.y(), p.z() + 30), 1e-9) << p.transpose();
    }
  }
  EXPECT_TRUE(met);
  EXPECT_LT((f.refs.back().position - wps[1].position).norm(), 1e-6);
}

TEST(WaypointGuidance, OffTheLegBesideTheLastWaypointItRejoinsAtTheWaypoint) {
  const std::vector<Waypoint> wps = {{Vec3(0, 0, -30), 2.0}, {Vec3(100, 0, -30), 2.0}};
  const Vec3 start(95, 3, -30);  // the leg ends 5 m on: the rejoin goes to its end
  PerfectFollower f(wps, 3.0, limits(3.0, 0.5, 1.0), start);
  ASSERT_TRUE(f.run(60));
  EXPECT_LT((f.refs.front().position - start).norm(), 1e-9);
  for (const GuidanceReference& r : f.refs) {
    EXPECT_LT(distance_to_segment(r.position, start, wps[1].position), 1e-9);
  }
  EXPECT_LT((f.refs.back().position - wps[1].position).norm(), 1e-6);
}

TEST(WaypointGuidance, RestartNearTheFirstLegStartsThere) {
  const std::vector<Waypoint> wps = {
      {Vec3(0, 0, -30), 5.0}, {Vec3(50, 0, -30), 5.0}, {Vec3(50, 50, -30), 5.0}};
  WaypointGuidance g;
  g.set_mission(wps, 3.0, limits(3.0, 0.5, 1.0), Vec3(20, 1, -30), Vec3::Zero());
  EXPECT_EQ(g.update(Vec3(20, 1, -30), Vec3::Zero(), kGuidancePeriod).active_waypoint, 1);
}

TEST(WaypointGuidance, VerticalLegRespectsMaxVerticalSpeed) {
  const double max_vertical = 1.0;
  // Straight up 30 m.
  {
    const std::vector<Waypoint> wps = {{Vec3(0, 0, -10), 2.0}, {Vec3(0, 0, -40), 2.0}};
    PerfectFollower f(wps, 3.0, limits(3.0, 0.5, max_vertical), wps[0].position);
    ASSERT_TRUE(f.run(120.0));
    double max_vz = 0;
    for (const auto& r : f.refs) {
      EXPECT_LE(std::abs(r.velocity.z()), max_vertical + 1e-9);
      EXPECT_GE(r.position.z(), -40.0 - 1e-9);  // never above the top waypoint
      max_vz = std::max(max_vz, std::abs(r.velocity.z()));
    }
    EXPECT_GT(max_vz, 0.95 * max_vertical);
    EXPECT_NEAR(f.refs.back().position.z(), -40.0, 2.0);
  }
  // A climbing leg: 30 m north, 30 m up; the climb rate is the limit, not
  // the cruise speed.
  {
    const std::vector<Waypoint> wps = {{Vec3(0, 0, -10), 2.0}, {Vec3(30, 0, -40), 2.0}};
    PerfectFollower f(wps, 3.0, limits(3.0, 0.5, max_vertical), wps[0].position);
    ASSERT_TRUE(f.run(200.0));
    double max_speed = 0;
    for (const auto& r : f.refs) {
      EXPECT_LE(std::abs(r.velocity.z()), max_vertical + 1e-9);
      max_speed = std::max(max_speed, r.velocity.norm());
    }
    // Along the leg at most max_vertical / sin(climb angle).
    const double slope_limit = max_vertical * std::hypot(30.0, 30.0) / 30.0;
    ASSERT_LT(slope_limit, 3.0);
    EXPECT_LE(max_speed, slope_limit + 1e-6);
    EXPECT_GT(max_speed, 0.95 * slope_limit);
  }
}

TEST(WaypointGuidance, ReferenceWaitsForALaggingVehicle) {
  const std::vector<Waypoint> wps = {{Vec3(0, 0, -30), 2.0}, {Vec3(200, 0, -30), 2.0}};
  const GuidanceConfig config;
  WaypointGuidance g(config);
  const Vec3 stuck(0, 0, -30);
  g.set_mission(wps, 3.0, limits(3.0, 0.5, 1.0), stuck, Vec3::Zero());
  const double max_accel = 0.5, cruise = 3.0;
  GuidanceReference r;
  for (int i = 0; i < 3000; ++i) r = g.update(stuck, Vec3::Zero(), kGuidancePeriod);
  const double after_30s = r.position.x();
  for (int i = 0; i < 3000; ++i) r = g.update(stuck, Vec3::Zero(), kGuidancePeriod);
  // The rubber band asks for zero speed two leads ahead; past that the
  // reference can only coast through its braking distance.
  const double braking = cruise * cruise / (2.0 * config.accel_fraction * max_accel);
  EXPECT_LE(r.position.x(), 2.0 * config.max_lead + braking);
  EXPECT_GT(r.position.x(), config.max_lead);
  EXPECT_NEAR(r.position.x(), after_30s, 1e-6);  // it has stopped
  EXPECT_LT(r.velocity.norm(), 1e-6);
  EXPECT_FALSE(r.done);
}

TEST(WaypointGuidance, ClearRemovesTheMission) {
  const std::vector<Waypoint> wps = {{Vec3(0, 0, -30), 2.0}, {Vec3(100, 0, -30), 2.0}};
  WaypointGuidance g;
  g.set_mission(wps, 3.0, limits(3.0, 0.5, 1.0), wps[0].position, Vec3::Zero());
  EXPECT_TRUE(g.has_mission());
  g.clear();
  EXPECT_FALSE(g.has_mission());
  EXPECT_EQ(g.update(Vec3::Zero(), Vec3::Zero(), kGuidancePeriod).active_waypoint, -1);
}

}  // namespace
}  // namespace ofn::control
