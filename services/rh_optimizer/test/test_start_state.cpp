// Where each RH step's plan starts: on the last plan while the vehicle is
// near it, else at the measured state.

#include <gtest/gtest.h>

#include <vector>

#include "ofn/rh_optimizer/start_state.hpp"

namespace ofn::rh {
namespace {

constexpr double kMaxAccel = 0.5;  // m/s^2

// Speeding up along north from rest, 1 m/s^2 over 4 s (a cubic B-spline
// with a single piece: control points from the Bezier form of 0.5 t^2).
BsplineTrajectory speeding_up() {
  const double T = 4.0, end = 0.5 * T * T;
  const std::vector<Vec3> points = {Vec3(0, 0, -30), Vec3(0, 0, -30), Vec3(end / 3.0, 0, -30),
                                    Vec3(end, 0, -30)};
  return BsplineTrajectory(3, {0, 0, 0, 0, 1, 1, 1, 1}, points, T);
}

MeasuredState measured_at(const Vec3& position, const Vec3& velocity) {
  return MeasuredState{position, velocity, Vec3(0.3, 0.4, 1.2)};
}

TEST(StartState, OnThePlanWhileTheVehicleIsNearIt) {
  const BsplineTrajectory plan = speeding_up();
  const StartState s = choose_start_state(plan, LastPlan::kMoving, 2.0,
                                          measured_at(Vec3(2.5, 1.0, -30), Vec3(2.3, 0.2, 0)),
                                          kMaxAccel, StartStateSettings{});
  EXPECT_TRUE(s.from_plan);
  EXPECT_TRUE(s.position.isApprox(plan.position(2.0)));
  EXPECT_TRUE(s.velocity.isApprox(plan.velocity(2.0)));
  EXPECT_TRUE(s.acceleration.isApprox(plan.acceleration(2.0)));
  EXPECT_NEAR(s.velocity.x(), 2.0, 1e-9);
}

TEST(StartState, AtTheVehicleWhenItIsOffThePlan) {
  const BsplineTrajectory plan = speeding_up();
  StartStateSettings rules;
  // 3.5 m off: beyond replan_position_error, with the plan's acceleration.
  StartState s =
      choose_start_state(plan, LastPlan::kMoving, 2.0,
                         measured_at(Vec3(5.5, 0, -30), Vec3(2, 0, 0)), kMaxAccel, rules);
  EXPECT_FALSE(s.from_plan);
  EXPECT_TRUE(s.position.isApprox(Vec3(5.5, 0, -30)));
  EXPECT_TRUE(s.acceleration.isApprox(plan.acceleration(2.0)));
  // 1.6 m/s off: beyond replan_velocity_error.
  s = choose_start_state(plan, LastPlan::kMoving, 2.0,
                         measured_at(plan.position(2.0), Vec3(0.4, 0, 0)), kMaxAccel, rules);
  EXPECT_FALSE(s.from_plan);
  EXPECT_TRUE(s.velocity.isApprox(Vec3(0.4, 0, 0)));
  // Starting on the plan switched off.
  rules.planned_initial_state = false;
  s = choose_start_state(plan, LastPlan::kMoving, 2.0,
                         measured_at(plan.position(2.0), plan.velocity(2.0)), kMaxAccel, rules);
  EXPECT_FALSE(s.from_plan);
}

TEST(StartState, NoPlanCoveringNowStartsAtTheVehicleWithoutAcceleration) {
  const MeasuredState vehicle = measured_at(Vec3(1, 2, -30), Vec3(3, 0, 0));
  for (const double since : {-0.1, 4.1}) {
    const StartState s = choose_start_state(speeding_up(), LastPlan::kMoving, since, vehicle,
                                            kMaxAccel, StartStateSettings{});
    EXPECT_FALSE(s.from_plan) << since;
    EXPECT_TRUE(s.position.isApprox(vehicle.position)) << since;
    EXPECT_TRUE(s.velocity.isApprox(vehicle.velocity)) << since;
    EXPECT_TRUE(s.acceleration.isZero()) << since;  // as guidance commands in cruise
  }
  const StartState none = choose_start_state(BsplineTrajectory(), LastPlan::kMoving, 0.0, vehicle,
                                             kMaxAccel, StartStateSettings{});
  EXPECT_FALSE(none.from_plan);
  EXPECT_TRUE(none.acceleration.isZero());
}

// A hover at (10, 0, -30): a stop that has come to rest.
BsplineTrajectory hover_at_rest() {
  const Vec3 point(10, 0, -30);
  return BsplineTrajectory(3, {0, 0, 0, 0, 1, 1, 1, 1}, {point, point, point, point}, 2.0);
}

TEST(StartState, AStopIsHeldAgainstAGustsVelocityAndOffset) {
  const BsplineTrajectory hover = hover_at_rest();
  // Pushed 4 m off the hover and moving at 3 m/s: past both replan errors
  // of a moving plan, but a stop is flown back to, not re-planned from the
  // pushed state (which would carry the 3 m/s on at the envelope's braking).
  const MeasuredState pushed = measured_at(Vec3(14, 0, -30), Vec3(3, 0, 0));
  const StartState held =
      choose_start_state(hover, LastPlan::kStop, 1.0, pushed, kMaxAccel, StartStateSettings{});
  EXPECT_TRUE(held.from_plan);
  EXPECT_TRUE(held.position.isApprox(Vec3(10, 0, -30)));
  EXPECT_TRUE(held.velocity.isZero());
  // The same reference as a moving plan is left for the vehicle's state.
  const StartState moved =
      choose_start_state(hover, LastPlan::kMoving, 1.0, pushed, kMaxAccel, StartStateSettings{});
  EXPECT_FALSE(moved.from_plan);
  EXPECT_TRUE(moved.velocity.isApprox(Vec3(3, 0, 0)));
}

TEST(StartState, AStopPastItsEndIsItsRestPoint) {
  const MeasuredState near = measured_at(Vec3(11, 0, -30), Vec3(0.5, 0, 0));
  const StartState held = choose_start_state(hover_at_rest(), LastPlan::kStop, 30.0, near,
                                             kMaxAccel, StartStateSettings{});
  EXPECT_TRUE(held.from_plan);
  EXPECT_TRUE(held.position.isApprox(Vec3(10, 0, -30)));
  // A moving plan past its end covers nothing.
  EXPECT_FALSE(choose_start_state(hover_at_rest(), LastPlan::kMoving, 30.0, near, kMaxAccel,
                                  StartStateSettings{})
                   .from_plan);
}

TEST(StartState, AStopTooFarToRecaptureStartsAtTheVehicle) {
  StartStateSettings rules;
  rules.stop_recapture_error = 6.0;
  const MeasuredState far = measured_at(Vec3(16.5, 0, -30), Vec3(0, 0, 0));
  const StartState s =
      choose_start_state(hover_at_rest(), LastPlan::kStop, 1.0, far, kMaxAccel, rules);
  EXPECT_FALSE(s.from_plan);
  EXPECT_TRUE(s.position.isApprox(far.position));
  rules.stop_recapture_error = 7.0;
  EXPECT_TRUE(
      choose_start_state(hover_at_rest(), LastPlan::kStop, 1.0, far, kMaxAccel, rules).from_plan);
  // 0 switches the hold off: a stop then follows a moving plan's rule.
  rules.stop_recapture_error = 0.0;
  const MeasuredState gusted = measured_at(Vec3(10.5, 0, -30), Vec3(2, 0, 0));
  EXPECT_FALSE(choose_start_state(hover_at_rest(), LastPlan::kStop, 1.0, gusted, kMaxAccel, rules)
                   .from_plan);
  EXPECT_FALSE(choose_start_state(hover_at_rest(), LastPlan::kStop, 30.0, gusted, kMaxAccel, rules)
                   .from_plan);
}

TEST(StartState, AMeasuredAccelerationIsCappedAtTheLimit) {
  StartStateSettings rules;
  rules.planned_initial_acceleration = false;
  // Off the plan: the measured acceleration, |(0.3, 0.4, 1.2)| = 1.3 capped to 0.5.
  const StartState s =
      choose_start_state(speeding_up(), LastPlan::kMoving, 2.0,
                         measured_at(Vec3(9, 0, -30), Vec3(2, 0, 0)), kMaxAccel, rules);
  EXPECT_FALSE(s.from_plan);
  EXPECT_NEAR(s.acceleration.norm(), kMaxAccel, 1e-12);
  EXPECT_TRUE(s.acceleration.normalized().isApprox(Vec3(0.3, 0.4, 1.2).normalized()));
}

}  // namespace
}  // namespace ofn::rh
