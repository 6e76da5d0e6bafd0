// The safety invariant of a published plan: continuous start, the envelope,
// and a stop into space seen free from every committed instant.

#include <gtest/gtest.h>

#include <memory>

#include "ofn/map/distance_field.hpp"
#include "ofn/rh_optimizer/commit_gate.hpp"
#include "ofn/rh_optimizer/rh_planner.hpp"
#include "rh_step_inputs.hpp"

namespace ofn::rh {
namespace {

using testing_support::untimed;

const Limits kLimits = testing_support::kBenchmarkLimits;
constexpr double kAltitude = testing_support::kLegAltitude;

// Straight and level along north at `speed` from north = 0 for `duration` s
// (a cubic B-spline with equally spaced control points is a straight line
// at constant speed).
BsplineTrajectory straight(double speed, double duration = 20.0) {
  const double length = speed * duration;
  std::vector<Vec3> points;
  for (int i = 0; i < 4; ++i) points.emplace_back(length * i / 3.0, 0.0, -kAltitude);
  return BsplineTrajectory(3, {0, 0, 0, 0, 1, 1, 1, 1}, points, duration);
}

FlownState start_of(const BsplineTrajectory& plan) {
  return FlownState{plan.position(0), plan.velocity(0), plan.acceleration(0)};
}

// A wall across the field from north `wall_north` on (top 80 m); none at
// 180 m or more.
ClearanceQuery wall_at(int wall_north) {
  return testing_support::field_with({{wall_north, 180, -60, 60, 80.0f}});
}

SeenQuery seen_up_to(double north_limit) {
  return [north_limit](double north, double) { return north < north_limit; };
}

TEST(CommitGate, AcceptsAPlanWhoseStopsStayInSeenFreeSpace) {
  const CommitGate gate;
  const BsplineTrajectory plan = straight(kLimits.max_speed);
  const CommitCheck c =
      gate.check(plan, 0.0, start_of(plan), kLimits, SafetyMap{wall_at(1000), seen_up_to(1000)});
  EXPECT_TRUE(c.committed) << c.reason;
  EXPECT_EQ(c.stops_checked, 11);  // every 0.1 s over the committed second
  EXPECT_GT(c.least_stop_clearance, kLimits.clearance);
}

TEST(CommitGate, RefusesAPlanWhoseStopRunsIntoUnseenSpace) {
  // Braking from 3 m/s at 0.8 a_max takes 11.9 m; unseen from 12 m on.
  const CommitGate gate;
  const BsplineTrajectory plan = straight(kLimits.max_speed);
  const CommitCheck refused =
      gate.check(plan, 0.0, start_of(plan), kLimits, SafetyMap{wall_at(1000), seen_up_to(12)});
  EXPECT_FALSE(refused.committed);
  EXPECT_NE(refused.reason.find("no beam has crossed"), std::string::npos) << refused.reason;
  // Seen far enough (the stops and half of R_s beyond them): accepted.
  const CommitCheck accepted =
      gate.check(plan, 0.0, start_of(plan), kLimits, SafetyMap{wall_at(1000), seen_up_to(30)});
  EXPECT_TRUE(accepted.committed) << accepted.reason;
  // Without a record of seen space, the rule is skipped.
  EXPECT_TRUE(
      gate.check(plan, 0.0, start_of(plan), kLimits, SafetyMap{wall_at(1000), {}}).committed);
}

TEST(CommitGate, RefusesAPlanWhoseStopComesWithinTheSafetyRadius) {
  const CommitGate gate;
  const BsplineTrajectory plan = straight(kLimits.max_speed);
  // Stops from the committed second end by north 3 + 11.9 = 15 m; R_s 6.1 m.
  const CommitCheck near =
      gate.check(plan, 0.0, start_of(plan), kLimits, SafetyMap{wall_at(19), seen_up_to(1000)});
  EXPECT_FALSE(near.committed);
  EXPECT_NE(near.reason.find("stop clearance"), std::string::npos) << near.reason;
  const CommitCheck far =
      gate.check(plan, 0.0, start_of(plan), kLimits, SafetyMap{wall_at(23), seen_up_to(1000)});
  EXPECT_TRUE(far.committed) << far.reason;
}

TEST(CommitGate, RefusesAStartOffTheReferenceFlown) {
  const CommitGate gate;
  const BsplineTrajectory plan = straight(kLimits.max_speed);
  FlownState flown = start_of(plan);
  flown.position.x() -= 16.0;  // the plan starts 16 m ahead of the reference
  const CommitCheck c = gate.check(plan, 0.0, flown, kLimits, SafetyMap{wall_at(1000), {}});
  EXPECT_FALSE(c.committed);
  EXPECT_NE(c.reason.find("position jump"), std::string::npos) << c.reason;
  flown = start_of(plan);
  flown.velocity.x() = 0.0;
  EXPECT_FALSE(gate.check(plan, 0.0, flown, kLimits, SafetyMap{wall_at(1000), {}}).committed);
}

TEST(CommitGate, RefusesAPlanOutsideTheEnvelope) {
  const CommitGate gate;
  const BsplineTrajectory fast = straight(1.03 * kLimits.max_speed);
  const CommitCheck c =
      gate.check(fast, 0.0, start_of(fast), kLimits, SafetyMap{wall_at(1000), {}});
  EXPECT_FALSE(c.committed);
  EXPECT_NE(c.reason.find("speed share"), std::string::npos) << c.reason;
  // Within the benchmarks' 2 %: accepted.
  const BsplineTrajectory near_limit = straight(1.015 * kLimits.max_speed);
  EXPECT_TRUE(
      gate.check(near_limit, 0.0, start_of(near_limit), kLimits, SafetyMap{wall_at(1000), {}})
          .committed);
}

TEST(CommitGate, AStartInsideTheSafetyRadiusMayNotGoDeeper) {
  const CommitGate gate;
  // Hovering 4 m from a wall (inside R_s = 6.1 m): staying is accepted,
  // moving towards it is not.
  const BsplineTrajectory hover = straight(0.0);
  const CommitCheck stay =
      gate.check(hover, 0.0, start_of(hover), kLimits, SafetyMap{wall_at(4), {}});
  EXPECT_TRUE(stay.committed) << stay.reason;
  const BsplineTrajectory creep = straight(0.5);
  const CommitCheck deeper =
      gate.check(creep, 0.0, start_of(creep), kLimits, SafetyMap{wall_at(4), {}});
  EXPECT_FALSE(deeper.committed);
}

TEST(CommitGate, UnseenDistanceIsToTheNearestUnseenCell) {
  const CommitGate gate;
  const SeenQuery seen = seen_up_to(10);
  EXPECT_NEAR(gate.unseen_distance(seen, Vec3(7.5, 0.3, 0), 5.0), 2.5, 1e-9);
  EXPECT_DOUBLE_EQ(gate.unseen_distance(seen, Vec3(0.0, 0.0, 0), 3.0), 3.0);  // capped
  EXPECT_DOUBLE_EQ(gate.unseen_distance(seen, Vec3(10.5, 0.0, 0), 3.0), 0.0);
}

// The planner: a plan without a safe stop is not committed, and a stop,
// once flown, is never left for the plan it replaced.
StepInput input_at(const Vec3& position, double time, ClearanceQuery clearance, SeenQuery seen) {
  StepInput input = testing_support::step_input_at(position, time, std::move(clearance));
  input.seen = std::move(seen);
  return input;
}

TEST(RhPlannerCommit, APlanWithoutASafeStopIsNotCommitted) {
  RhPlanner planner(untimed());
  // Open space, but nothing seen beyond 5 m ahead: every forward plan's
  // stop runs into unseen space.
  const StepOutput out =
      planner.step(input_at(Vec3(0, 0, -kAltitude), 10.0, wall_at(1000), seen_up_to(5)));
  EXPECT_EQ(out.mode, StepMode::kBraking) << out.reason;
  EXPECT_GE(out.refused, 1);
  EXPECT_NE(out.reason.find("refused"), std::string::npos) << out.reason;
  // The stop flown starts on the state flown now.
  EXPECT_LT((out.trajectory.position(0) - Vec3(0, 0, -kAltitude)).norm(), 1e-9);
  EXPECT_LT((out.trajectory.velocity(0) - Vec3(kLimits.max_speed, 0, 0)).norm(), 1e-9);
  // Seen far ahead, the same problem is solved and committed.
  RhPlanner seeing;
  const StepOutput solved =
      seeing.step(input_at(Vec3(0, 0, -kAltitude), 10.0, wall_at(1000), seen_up_to(1000)));
  EXPECT_EQ(solved.mode, StepMode::kSolved) << solved.reason;
  EXPECT_TRUE(solved.commit.committed);
}

TEST(RhPlannerCommit, AfterBrakingAFailureNeverReturnsToTheOldPlan) {
  // The plan of t = 10 s, then a step that must brake (the vehicle inside
  // half of R_s), then, seconds later, a failing step: the old plan, 16 m
  // ahead of the braked vehicle by then, must not be kept.
  FallbackSettings fallback;
  fallback.cold_retry = false;
  RhPlanner planner(untimed(), fallback);
  const StepOutput first =
      planner.step(input_at(Vec3(0, 0, -kAltitude), 10.0, wall_at(1000), seen_up_to(1000)));
  ASSERT_EQ(first.mode, StepMode::kSolved) << first.reason;
  ASSERT_TRUE(planner.has_previous());
  const StepOutput braked =
      planner.step(input_at(Vec3(0.3, 0, -kAltitude), 10.1, wall_at(2), seen_up_to(1000)));
  ASSERT_EQ(braked.mode, StepMode::kBraking) << braked.reason;
  EXPECT_FALSE(planner.has_previous());
  // Five seconds on, on the stop, a problem no plan can meet (x_f beyond
  // what 60 s at the speed limit reach), so the solve fails.
  StepInput later =
      input_at(braked.trajectory.position(5.0), 15.1, wall_at(1000), seen_up_to(1000));
  later.problem.velocity = braked.trajectory.velocity(5.0);
  later.problem.terminal_x = later.problem.position.x() + 1000.0;
  const StepOutput out = planner.step(later);
  EXPECT_EQ(out.mode, StepMode::kBraking) << out.reason;
  EXPECT_LT((out.trajectory.position(0) - later.problem.position).norm(), 1e-9);
}

}  // namespace
}  // namespace ofn::rh
