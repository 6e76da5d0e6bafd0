// One receding-horizon step with its warm starts and fallbacks: solved,
// keep the previous trajectory, or brake to a hover.

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <utility>

#include "ofn/map/distance_field.hpp"
#include "ofn/rh_optimizer/rh_planner.hpp"
#include "rh_step_inputs.hpp"

namespace ofn::rh {
namespace {

const Limits kPlannerLimits = testing_support::kBenchmarkLimits;
constexpr double kCruiseAltitude = testing_support::kLegAltitude;

using testing_support::Box;
using testing_support::field_with;
using testing_support::untimed;

StepInput input_at(const Vec3& position, double time, ClearanceQuery clearance) {
  return testing_support::step_input_at(position, time, std::move(clearance));
}

// The next step's input: the state `out` planned 0.1 s on, at `time`.
StepInput one_step_on(const StepOutput& out, double time) {
  StepInput next = input_at(out.trajectory.position(0.1), time, field_with({}));
  next.problem.velocity = out.trajectory.velocity(0.1);
  next.problem.acceleration = out.trajectory.acceleration(0.1);
  return next;
}

bool finite(const BsplineTrajectory& trajectory) {
  if (trajectory.empty() || !std::isfinite(trajectory.duration())) return false;
  for (const Vec3& c : trajectory.control_points())
    if (!c.allFinite()) return false;
  return true;
}

TEST(RhPlanner, SolvesACleanProblemAndWarmStartsTheNext) {
  RhPlanner planner(untimed());
  const StepInput first = input_at(Vec3(0, 0, -kCruiseAltitude), 10.0, field_with({}));
  const StepOutput out = planner.step(first);
  ASSERT_EQ(out.mode, StepMode::kSolved) << out.reason;
  EXPECT_EQ(out.solves, 1);
  EXPECT_DOUBLE_EQ(out.start_time, 10.0);
  EXPECT_TRUE(finite(out.trajectory));
  EXPECT_FALSE(out.report.warm_started);
  EXPECT_TRUE(planner.has_previous());

  const StepInput second = one_step_on(out, 10.1);
  const StepOutput next = planner.step(second);
  ASSERT_EQ(next.mode, StepMode::kSolved) << next.reason;
  EXPECT_TRUE(next.report.warm_started);
  EXPECT_DOUBLE_EQ(next.start_time, 10.1);

  // A new route makes the next guess cold again.
  StepInput rerouted = second;
  rerouted.time = 10.2;
  rerouted.global_path_changed = true;
  rerouted.global_path = {Vec3(0, 0, -kCruiseAltitude), Vec3(300, 0, -kCruiseAltitude)};
  const StepOutput cold = planner.step(rerouted);
  ASSERT_EQ(cold.mode, StepMode::kSolved) << cold.reason;
  EXPECT_FALSE(cold.report.warm_started);

  planner.reset();
  EXPECT_FALSE(planner.has_previous());
}

// Quadratic B-splines over `duration` seconds through four control points.
BsplineTrajectory quadratic(const std::vector<Vec3>& points, double duration) {
  return BsplineTrajectory(2, {0, 0, 0, 0.5, 1, 1, 1}, points, duration);
}

TEST(RhPlanner, APlanThatWaitsBeforeItMovesOffIsAStall) {
  const Vec3 start(0, 0, -kCruiseAltitude);
  const Vec3 far(60, 30, -kCruiseAltitude);
  RhProblem problem = input_at(start, 0.0, field_with({})).problem;
  problem.velocity = Vec3::Zero();
  // Hovers for the first half (three coincident points), then goes 67 m.
  const BsplineTrajectory waits = quadratic({start, start, start, far}, 20.0);
  EXPECT_TRUE(plan_stalled(waits, problem));
  // Moves off at once: no stall, however slow the vehicle is now.
  const BsplineTrajectory goes =
      quadratic({start, start + (far - start) / 3, start + 2 * (far - start) / 3, far}, 20.0);
  EXPECT_FALSE(plan_stalled(goes, problem));
  // A short leg that waits is a stall too: an escape 8 m to the side.
  const Vec3 aside = start + Vec3(-1, 8, 0);
  EXPECT_TRUE(plan_stalled(quadratic({start, start, start, aside}, 20.0), problem));
  // A stop at the last waypoint that ends near its start: not a stall.
  const Vec3 near = start + Vec3(2, 0, 0);
  EXPECT_FALSE(plan_stalled(quadratic({start, start, start, near}, 20.0), problem));
  // The vehicle itself still moving: not a stall either (the plan brakes).
  problem.velocity = Vec3(kPlannerLimits.max_speed, 0, 0);
  EXPECT_FALSE(plan_stalled(waits, problem));
}

TEST(RhPlanner, AShortStopFromAHoverIsSolvedColdAndMovesOffInTime) {
  // A hover a few metres before the last waypoint (after a look round or an
  // escape), with no route to guess from: the straight guess speeds up and
  // slows down. At constant speed it asked for a step in velocity and no
  // stop 1-5 m on was solved. And the stall's least displacement is set so
  // that a healthy plan to a stop just beyond it is no longer slow at the
  // look-ahead.
  for (const double distance : {1.0, 2.0, kStallMinDisplacement + 0.1, 5.0}) {
    RhPlanner planner(untimed());
    StepInput in = input_at(Vec3(0, 0, -kCruiseAltitude), 0.0, field_with({}));
    in.problem.velocity = Vec3::Zero();
    in.problem.target = in.problem.position + Vec3(distance, 0, 0);
    in.problem.terminal_x = in.problem.frame.to_guidance(in.problem.target).x();
    in.problem.stop_at_target = true;
    const StepOutput out = planner.step(in);
    ASSERT_EQ(out.mode, StepMode::kSolved) << distance << " m: " << out.reason;
    const double T = out.trajectory.duration();
    EXPECT_LT((out.trajectory.position(T) - in.problem.target).norm(), 0.05) << distance << " m";
    if (distance > kStallMinDisplacement) {
      EXPECT_FALSE(plan_stalled(out.trajectory, in.problem))
          << distance << " m, speed 3 s on: " << out.trajectory.velocity(kStallLookAhead).norm()
          << " m/s";
    }
  }
}

TEST(RhPlanner, FromAHoverAFailedRouteGuessIsTriedStraight) {
  // A hover 5 m before a stop (an escape leg's end), on a route whose first
  // corner lies 5 mm below the vehicle, as on dense seed 142 (the vehicle
  // had settled a few millimetres off the point the escape began at): no
  // feasible point is found from the route's guess. At rest, every step
  // would pose the same problem and fail the same way; from the straight
  // guess, millimetres away, it solves. (Which guesses fail turns on
  // details: here a column stands 4 m to the side.)
  const ClearanceQuery column = field_with({{-2, 0, 4, 6, 60.0f}});
  auto hover_input = [&]() {
    StepInput in = input_at(Vec3(0, 0, -kCruiseAltitude), 0.0, column);
    in.problem.velocity = Vec3::Zero();
    in.problem.target = in.problem.position + Vec3(5, 0, 0);
    in.problem.terminal_x = in.problem.frame.to_guidance(in.problem.target).x();
    in.problem.stop_at_target = true;
    in.global_path = {Vec3(0, 0, -kCruiseAltitude), Vec3(0, 0, -kCruiseAltitude + 0.005),
                      Vec3(5, 0, -kCruiseAltitude)};
    return in;
  };
  FallbackSettings without;
  without.hover_retry = false;
  without.short_retry = false;
  RhPlanner route_only(untimed(), without);
  const StepOutput failed = route_only.step(hover_input());
  ASSERT_NE(failed.mode, StepMode::kSolved) << "the route's guess solved: the case is gone";

  FallbackSettings with = without;
  with.hover_retry = true;
  RhPlanner planner(untimed(), with);
  const StepOutput out = planner.step(hover_input());
  ASSERT_EQ(out.mode, StepMode::kSolved) << out.reason;
  EXPECT_EQ(out.solves, 2);
  const double T = out.trajectory.duration();
  EXPECT_LT((out.trajectory.position(T) - hover_input().problem.target).norm(), 0.05);

  // Moving, the next step poses another problem: no retry.
  StepInput moving = hover_input();
  moving.problem.velocity = Vec3(0.5, 0, 0);
  RhPlanner moving_planner(untimed(), with);
  EXPECT_EQ(moving_planner.step(moving).solves, 1);
}

TEST(RhPlanner, AHealthyWarmStepFromRestSolvesOnce) {
  // From a hover, the plan moves off at once, so the stall retry stays out
  // of the way: one solve per step.
  RhPlanner planner(untimed());
  StepInput first = input_at(Vec3(0, 0, -kCruiseAltitude), 0.0, field_with({}));
  first.problem.velocity = Vec3::Zero();
  const StepOutput out = planner.step(first);
  ASSERT_EQ(out.mode, StepMode::kSolved) << out.reason;
  EXPECT_FALSE(plan_stalled(out.trajectory, first.problem));
  const StepOutput next = planner.step(one_step_on(out, 0.1));
  ASSERT_EQ(next.mode, StepMode::kSolved) << next.reason;
  EXPECT_TRUE(next.report.warm_started);
  EXPECT_EQ(next.solves, 1);
  EXPECT_FALSE(next.stalled);
  EXPECT_TRUE(next.reason.empty()) << next.reason;
}

TEST(RhPlanner, KeepsThePreviousWhenTheSolveFailsAndThePreviousIsSafe) {
  RhPlanner planner(untimed());
  const ClearanceQuery open = field_with({});
  const StepOutput first = planner.step(input_at(Vec3(0, 0, -kCruiseAltitude), 5.0, open));
  ASSERT_EQ(first.mode, StepMode::kSolved);

  // A terminal x out of reach within max_duration at max_speed.
  StepInput impossible = input_at(first.trajectory.position(0.5), 5.5, open);
  impossible.problem.velocity = first.trajectory.velocity(0.5);
  impossible.problem.terminal_x = 1000.0;
  const StepOutput out = planner.step(impossible);
  EXPECT_EQ(out.mode, StepMode::kKeptPrevious) << out.reason;
  EXPECT_EQ(out.solves, 2);  // the warm solve and the cold retry
  EXPECT_DOUBLE_EQ(out.start_time, 5.0);
  EXPECT_EQ(out.trajectory.control_points(), first.trajectory.control_points());
  EXPECT_FALSE(out.reason.empty());

  // Without the retry only one solve runs.
  FallbackSettings no_retries;
  no_retries.cold_retry = false;
  RhPlanner no_retry(RhSettings{}, no_retries);
  ASSERT_EQ(no_retry.step(input_at(Vec3(0, 0, -kCruiseAltitude), 5.0, open)).mode,
            StepMode::kSolved);
  EXPECT_EQ(no_retry.step(impossible).solves, 1);
}

TEST(RhPlanner, KeepsAStopAtTheWaypointToItsEndButNotAPlanStillMoving) {
  const ClearanceQuery open = field_with({});
  // A step whose solve cannot succeed (terminal x out of reach), `left`
  // seconds before the end of the plan `first` started at time 0.
  auto failing_step_before_end = [&](const StepOutput& first, double left) {
    const double t = first.trajectory.duration() - left;
    StepInput later = input_at(first.trajectory.position(t), t, open);
    later.problem.velocity = first.trajectory.velocity(t);
    later.problem.acceleration = first.trajectory.acceleration(t);  // as the service starts it
    later.problem.terminal_x = 1000.0;
    return later;
  };

  // Still at cruise speed where it ends: with 1 s left there is no time for
  // the braking after it, so brake now.
  RhPlanner passing(untimed());
  const StepOutput moving = passing.step(input_at(Vec3(0, 0, -kCruiseAltitude), 0.0, open));
  ASSERT_EQ(moving.mode, StepMode::kSolved) << moving.reason;
  ASSERT_GT(moving.trajectory.velocity(moving.trajectory.duration()).norm(), 1.0);
  EXPECT_EQ(passing.step(failing_step_before_end(moving, 1.0)).mode, StepMode::kBraking);

  // Ending at rest on the last waypoint: it is kept to its end, and stops
  // there rather than wherever braking would.
  RhPlanner stopping;
  StepInput last_leg = input_at(Vec3(260, 0, -kCruiseAltitude), 0.0, open);
  last_leg.problem.terminal_x = 300.0;
  last_leg.problem.stop_at_target = true;
  const StepOutput stop = stopping.step(last_leg);
  ASSERT_EQ(stop.mode, StepMode::kSolved) << stop.reason;
  const StepOutput kept = stopping.step(failing_step_before_end(stop, 1.0));
  EXPECT_EQ(kept.mode, StepMode::kKeptPrevious) << kept.reason;
  EXPECT_EQ(kept.trajectory.control_points(), stop.trajectory.control_points());
  // Once it has ended, it is no longer kept.
  EXPECT_EQ(stopping.step(failing_step_before_end(stop, -0.5)).mode, StepMode::kBraking);
}

TEST(RhPlanner, KeepsThePreviousWhenTheIterationLimitStopsTheSolve) {
  RhSettings one_evaluation = untimed();
  one_evaluation.max_iterations = 1;
  RhPlanner planner(one_evaluation);
  // Straight and level at cruise speed: the straight guess is itself feasible.
  const StepOutput first =
      planner.step(input_at(Vec3(0, 0, -kCruiseAltitude), 0.0, field_with({})));
  ASSERT_EQ(first.mode, StepMode::kSolved) << first.reason;

  // A new zig-zag route: one evaluation of its guess cannot be feasible.
  StepInput later = input_at(first.trajectory.position(0.3), 0.3, field_with({}));
  later.global_path_changed = true;
  later.global_path = {Vec3(0, 0, -kCruiseAltitude), Vec3(15, 20, -kCruiseAltitude),
                       Vec3(30, -20, -kCruiseAltitude), Vec3(300, 0, -kCruiseAltitude)};
  const StepOutput out = planner.step(later);
  EXPECT_EQ(out.mode, StepMode::kKeptPrevious) << out.reason;
  EXPECT_EQ(out.report.iterations, 1);
  EXPECT_EQ(out.solves, 1);  // a cold guess is not retried
  EXPECT_DOUBLE_EQ(out.start_time, 0.0);
}

TEST(RhPlanner, BrakesWhenTheStartIsInsideTheClearance) {
  RhPlanner planner(untimed());
  // A tall wall 2 m ahead of the vehicle.
  const ClearanceQuery wall = field_with({{2, 4, -60, 60, 70.0f}});
  const StepInput input = input_at(Vec3(0, 0, -kCruiseAltitude), 3.0, wall);
  ASSERT_LT(input.problem.clearance(input.problem.position).distance,
            0.5 * kPlannerLimits.clearance);
  const StepOutput out = planner.step(input);
  EXPECT_EQ(out.mode, StepMode::kBraking);
  EXPECT_EQ(out.solves, 0);
  EXPECT_EQ(out.report.iterations, 0);
  EXPECT_DOUBLE_EQ(out.start_time, 3.0);
  EXPECT_FALSE(out.reason.empty());
  EXPECT_LT((out.trajectory.position(0) - input.problem.position).norm(), 1e-9);
  EXPECT_LT((out.trajectory.velocity(0) - input.problem.velocity).norm(), 1e-9);
}

TEST(RhPlanner, BrakesWhenThePreviousRunsIntoANewObstacle) {
  RhPlanner planner(untimed());
  const StepOutput first =
      planner.step(input_at(Vec3(0, 0, -kCruiseAltitude), 0.0, field_with({})));
  ASSERT_EQ(first.mode, StepMode::kSolved);
  // A wall across the whole map, higher than the field, pops up 25 m ahead:
  // no solution passes it and the previous trajectory runs into it.
  const ClearanceQuery wall = field_with({{25, 28, -60, 60, 200.0f}});
  StepInput input = input_at(first.trajectory.position(0.2), 0.2, wall);
  input.problem.velocity = first.trajectory.velocity(0.2);
  const StepOutput out = planner.step(input);
  EXPECT_EQ(out.mode, StepMode::kBraking) << out.reason;
  EXPECT_NE(out.reason.find("previous"), std::string::npos) << out.reason;
  EXPECT_TRUE(finite(out.trajectory));
  EXPECT_DOUBLE_EQ(out.start_time, 0.2);
}

// While the stop is flown, the retries (here the plan to a nearer x) wait
// for braking_retry_period; the step's own solve runs at every step.
TEST(RhPlanner, WhileAStopIsFlownTheRetriesWaitForTheirPeriod) {
  // The wall across the whole map 25 m ahead: nothing passes it, nor stops
  // short of it with R_s to spare from this speed.
  const ClearanceQuery wall = field_with({{25, 28, -60, 60, 200.0f}});
  // The state `flown` is at `since` s on, as the step at `time` s.
  auto step_on = [&](RhPlanner& planner, const StepOutput& flown, double since, double time) {
    StepInput in = input_at(flown.trajectory.position(since), time, wall);
    in.problem.velocity = flown.trajectory.velocity(since);
    in.problem.acceleration = flown.trajectory.acceleration(since);
    return planner.step(in);
  };
  // A plan in the open at t = 0, then the wall at 0.2 s: a brake.
  auto braked_by_the_wall = [&](RhPlanner& planner) {
    const StepOutput first =
        planner.step(input_at(Vec3(0, 0, -kCruiseAltitude), 0.0, field_with({})));
    EXPECT_EQ(first.mode, StepMode::kSolved) << first.reason;
    return step_on(planner, first, 0.2, 0.2);
  };

  FallbackSettings fallback;
  fallback.braking_retry_period = 0.5;
  RhPlanner planner(untimed(), fallback);
  const StepOutput braked = braked_by_the_wall(planner);
  ASSERT_EQ(braked.mode, StepMode::kBraking) << braked.reason;
  // The warm solve, the cold retry and the nearer x.
  EXPECT_EQ(braked.solves, 3);
  StepOutput flown = braked;
  for (int k = 1; k <= 4; ++k) {  // 0.3 .. 0.6 s: within 0.5 s of the retry
    const double time = 0.2 + 0.1 * k;
    const StepOutput next = step_on(planner, flown, 0.1, time);
    ASSERT_EQ(next.mode, StepMode::kBraking) << next.reason;
    EXPECT_EQ(next.solves, 1) << "at " << time << " s";  // the step's own solve alone
    flown = next;
  }
  // 0.5 s on, the nearer x is tried again.
  const StepOutput due = step_on(planner, flown, 0.1, 0.7);
  ASSERT_EQ(due.mode, StepMode::kBraking) << due.reason;
  EXPECT_EQ(due.solves, 2);

  // With no period, every braking step retries.
  FallbackSettings every_step = fallback;
  every_step.braking_retry_period = 0.0;
  RhPlanner eager(untimed(), every_step);
  const StepOutput eager_braked = braked_by_the_wall(eager);
  ASSERT_EQ(eager_braked.mode, StepMode::kBraking) << eager_braked.reason;
  EXPECT_EQ(step_on(eager, eager_braked, 0.1, 0.3).solves, 2);
}

TEST(RhPlanner, KeepsThePreviousPastAConflictBeyondTheBrakingWindow) {
  // A wall across the whole map, higher than the field, 55 m ahead: no
  // solution passes it, and the previous plan, made before it was seen,
  // comes within R_s of it 16 s on.
  auto fail_against_wall_at = [](double wall_north) {
    // Without the retry to a nearer x, which finds a plan that stays short
    // of the wall (RhPlanner.NearerTerminalXWhenNoPlanReachesTheHorizon).
    FallbackSettings fallback;
    fallback.short_retry = false;
    RhPlanner planner(untimed(), fallback);
    const StepOutput first =
        planner.step(input_at(Vec3(0, 0, -kCruiseAltitude), 0.0, field_with({})));
    EXPECT_EQ(first.mode, StepMode::kSolved) << first.reason;
    const int north = static_cast<int>(wall_north);
    StepInput input = input_at(first.trajectory.position(0.2), 0.2,
                               field_with({{north, north + 3, -60, 60, 200.0f}}));
    input.problem.velocity = first.trajectory.velocity(0.2);
    return std::make_pair(planner.braking_window(input.problem), planner.step(input));
  };
  // 10.2 s: braking from 3.048 m/s at 0.8 of 0.4877 m/s^2 with its 0.8 s
  // ease-out, plus the 2 s kept.
  const auto [window, far] = fail_against_wall_at(55.0);
  EXPECT_NEAR(window, 3.048 / (0.8 * 0.4877) + 0.5 * (kStopOnsetTime + kStopRampTime) + 2.0, 1e-9);
  EXPECT_EQ(far.mode, StepMode::kKeptPrevious) << far.reason;
  EXPECT_DOUBLE_EQ(far.start_time, 0.0);
  // The same wall 30 m ahead, met 7.6 s on, inside the window: brake now.
  const auto near = fail_against_wall_at(30.0).second;
  EXPECT_EQ(near.mode, StepMode::kBraking) << near.reason;
  EXPECT_NE(near.reason.find("previous comes within"), std::string::npos) << near.reason;
}

// A wall across the whole map pops up 30 m ahead: no plan passes it, and the
// previous one meets it within the braking window, so it cannot be kept.
// Before the stop, a plan to a nearer x (here 0.3 of the way to the horizon)
// is tried: it stays short of the wall, its stops are clear, it is flown.
TEST(RhPlanner, PlansToANearerXBeforeItStops) {
  FallbackSettings fallback;
  fallback.short_retry_fraction = 0.3;
  RhPlanner planner(untimed(), fallback);
  const StepOutput first =
      planner.step(input_at(Vec3(0, 0, -kCruiseAltitude), 0.0, field_with({})));
  ASSERT_EQ(first.mode, StepMode::kSolved) << first.reason;
  StepInput input =
      input_at(first.trajectory.position(0.2), 0.2, field_with({{30, 33, -60, 60, 200.0f}}));
  input.problem.velocity = first.trajectory.velocity(0.2);
  const StepOutput out = planner.step(input);
  ASSERT_EQ(out.mode, StepMode::kSolved) << out.reason;
  EXPECT_NE(out.reason.find("nearer x"), std::string::npos) << out.reason;
  EXPECT_TRUE(out.commit.committed) << out.commit.reason;
  const double x0 = input.problem.position.x();
  const double x_end = out.trajectory.position(out.trajectory.duration()).x();
  EXPECT_NEAR(x_end, x0 + 0.3 * (input.problem.terminal_x - x0), 0.5);
  EXPECT_LT(x_end, 30.0 - kPlannerLimits.clearance);
}

TEST(RhPlanner, BrakingTrajectoryStopsWithinTheBrakingAcceleration) {
  const FallbackSettings fallback;
  const RhPlanner planner(untimed(), fallback);
  const double limit = fallback.braking_accel_fraction * kPlannerLimits.max_accel;
  for (const Vec3& velocity :
       {Vec3(3.0, 0, 0), Vec3(1.5, -2.0, 0.8), Vec3(0.05, 0.02, 0), Vec3(0, 0, 0)}) {
    RhProblem problem;
    problem.position = Vec3(10, -4, -25);
    problem.velocity = velocity;
    problem.acceleration = Vec3(0.3, 0.1, 0);
    problem.limits = kPlannerLimits;
    const BsplineTrajectory braking = planner.braking_trajectory(problem);
    ASSERT_TRUE(finite(braking));
    EXPECT_LT((braking.position(0) - problem.position).norm(), 1e-9);
    EXPECT_LT((braking.velocity(0) - velocity).norm(), 1e-9);
    // From the start's acceleration along the velocity, not a step.
    if (velocity.norm() > 0.1) {
      EXPECT_NEAR(braking.acceleration(0).dot(velocity.normalized()),
                  problem.acceleration.dot(velocity.normalized()), 1e-9);
    }
    const double T = braking.duration();
    EXPECT_LT(braking.velocity(T).norm(), 1e-9);
    EXPECT_LT(braking.velocity(T + 5.0).norm(), 1e-9);
    // Exactly the stop of braking.hpp that the gate checks and the
    // controller flies.
    const StopProfile stop = stop_from(problem.position, velocity, problem.acceleration, limit);
    for (int k = 0; k <= 500; ++k) {
      const double t = T * k / 500.0;
      EXPECT_LE(braking.acceleration(t).norm(), limit + 1e-9) << "t " << t;
      EXPECT_LT((braking.position(t) - stop.position(t)).norm(), 1e-9) << "t " << t;
      EXPECT_LT((braking.velocity(t) - stop.velocity_at(t)).norm(), 1e-9) << "t " << t;
      EXPECT_LT((braking.acceleration(t) - stop.acceleration_at(t)).norm(), 1e-8) << "t " << t;
      // Along the velocity: never turning; faster only by what the onset
      // from the speeding-up start adds.
      if (velocity.norm() > 0) {
        EXPECT_GE(braking.velocity(t).dot(velocity), -1e-9);
        EXPECT_LE(
            braking.velocity(t).norm(),
            velocity.norm() + std::max(0.0, stop.start_acceleration) * stop.onset_time + 1e-9);
      }
    }
    EXPECT_LT((braking.position(T) - stop.stop_point()).norm(), 1e-9);
  }
}

TEST(RhPlanner, NonFiniteInputBrakesWithoutNaN) {
  RhPlanner planner(untimed());
  StepInput input = input_at(Vec3(0, 0, -kCruiseAltitude), 1.0, field_with({}));
  input.problem.velocity.y() = std::nan("");
  const StepOutput out = planner.step(input);
  EXPECT_EQ(out.mode, StepMode::kBraking);
  EXPECT_TRUE(finite(out.trajectory));
  EXPECT_STREQ(to_string(StepMode::kKeptPrevious), "kept_previous");
}

}  // namespace
}  // namespace ofn::rh
