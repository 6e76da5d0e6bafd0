// What one RH step solves: the problem framed along the active leg, or
// along a dead-end recovery's escape leg, and when a plan moves off.

#include <gtest/gtest.h>

#include "ofn/rh_optimizer/step_problem.hpp"
#include "rh_step_inputs.hpp"

namespace ofn::rh {
namespace {

using testing_support::Box;
using testing_support::field_with;
using testing_support::kBenchmarkLimits;
using testing_support::kLegAltitude;

const Leg kStraightLeg{Vec3(0, 0, -kLegAltitude), Vec3(300, 0, -kLegAltitude)};

// Nothing mapped over north [-20, 180), east [-60, 60).
mapping::Heightfield open_grid() {
  return testing_support::heightfield_with({});
}

StartState start_at(const Vec3& position) {
  StartState start;
  start.position = position;
  start.velocity = Vec3(kBenchmarkLimits.max_speed, 0, 0);
  start.acceleration = Vec3(0.1, 0, 0);
  return start;
}

FramingSettings framing(double max_shift = 3.0) {
  FramingSettings s;
  s.clearance_margin = 0.3;
  s.pinch_clearance = (kBenchmarkLimits.clearance + 0.3) * 0.99;
  s.max_shift = max_shift;
  return s;
}

TEST(LegProblem, StartsWhereToldAndEndsAtTheSensorsReachAlongTheLeg) {
  const Vec3 vehicle(100, 1, -kLegAltitude);
  const RhProblem p = leg_problem(kStraightLeg, true, start_at(vehicle), vehicle, kBenchmarkLimits,
                                  field_with({}), open_grid(), framing());
  EXPECT_EQ(p.position, vehicle);
  EXPECT_EQ(p.velocity, Vec3(kBenchmarkLimits.max_speed, 0, 0));
  EXPECT_EQ(p.acceleration, Vec3(0.1, 0, 0));
  EXPECT_EQ(p.target, kStraightLeg.to);
  EXPECT_NEAR(p.frame.to_guidance(kStraightLeg.to).x(), 300.0, 1e-9);
  // Open space: the horizon is the sensor's reach from the vehicle.
  EXPECT_NEAR(p.terminal_x, 100.0 + kBenchmarkLimits.sensor_range, 1e-9);
  EXPECT_FALSE(p.stop_at_target);  // the last waypoint is beyond the horizon
  EXPECT_EQ(p.limits.min_forward_speed, kBenchmarkLimits.min_forward_speed);
  ASSERT_TRUE(static_cast<bool>(p.clearance));
}

TEST(LegProblem, StopsAtTheTargetOnlyOnTheLastLegWithinTheHorizon) {
  const Vec3 vehicle(250, 0, -kLegAltitude);
  const RhProblem last = leg_problem(kStraightLeg, true, start_at(vehicle), vehicle,
                                     kBenchmarkLimits, field_with({}), open_grid(), framing());
  EXPECT_NEAR(last.terminal_x, 300.0, 1e-9);  // never past the target
  EXPECT_TRUE(last.stop_at_target);
  const RhProblem inner = leg_problem(kStraightLeg, false, start_at(vehicle), vehicle,
                                      kBenchmarkLimits, field_with({}), open_grid(), framing());
  EXPECT_FALSE(inner.stop_at_target);
}

TEST(FrameEscape, EndsAtTheCornerWhereThereIsRoomAndRelaxesOnlyTheForwardSpeed) {
  const Vec3 vehicle(100, 0, -kLegAltitude);
  RhProblem p = leg_problem(kStraightLeg, false, start_at(vehicle), vehicle, kBenchmarkLimits,
                            field_with({}), open_grid(), framing());
  const Vec3 from(100, 0, -kLegAltitude), corner(80, 20, -kLegAltitude);
  const Vec3 end = frame_escape(&p, from, corner, vehicle, open_grid(), framing());
  EXPECT_EQ(end, corner);
  EXPECT_EQ(p.target, corner);
  // The frame runs from where the escape began towards its end, backwards
  // over the leg: the forward-speed rule is relaxed to the speed limit.
  EXPECT_NEAR(p.frame.to_guidance(from).x(), 0.0, 1e-9);
  EXPECT_NEAR(p.frame.to_guidance(corner).x(), (corner - from).norm(), 1e-9);
  EXPECT_TRUE(p.stop_at_target);  // 28 m away, inside the sensor's reach
  EXPECT_EQ(p.limits.min_forward_speed, -kBenchmarkLimits.max_speed);
  EXPECT_EQ(p.limits.max_speed, kBenchmarkLimits.max_speed);
  EXPECT_EQ(p.limits.clearance, kBenchmarkLimits.clearance);
  EXPECT_EQ(p.position, vehicle);  // the start is not touched
}

TEST(FrameEscape, MovesACrampedEndToTheNearestRoomWithinTheShiftOrKeepsTheCorner) {
  // A tall block east of east = 0; the corner 3 m from its face.
  const ClearanceQuery clearance = field_with({Box{50, 70, 0, 40, 60.0f}});
  const Vec3 vehicle(30, -10, -kLegAltitude), corner(60, -3, -kLegAltitude);
  const double planned = kBenchmarkLimits.clearance + 0.3;
  ASSERT_LT(clearance(corner).distance, planned);

  RhProblem p = leg_problem(kStraightLeg, false, start_at(vehicle), vehicle, kBenchmarkLimits,
                            clearance, open_grid(), framing(5.0));
  const Vec3 end = frame_escape(&p, vehicle, corner, vehicle, open_grid(), framing(5.0));
  // Room with the planned clearance and its margin, within the shift.
  EXPECT_GE(clearance(end).distance, planned + kEscapeEndMargin - 1e-3);
  EXPECT_LE((end - corner).norm(), 5.0 + 1e-9);
  EXPECT_EQ(p.target, end);

  // No room within half a metre: the corner itself (the route check tells
  // the global planner about such corners; the escape does not invent one).
  RhProblem q = leg_problem(kStraightLeg, false, start_at(vehicle), vehicle, kBenchmarkLimits,
                            clearance, open_grid(), framing(0.5));
  EXPECT_EQ(frame_escape(&q, vehicle, corner, vehicle, open_grid(), framing(0.5)), corner);
}

TEST(PlanMovesOff, OnlyASolvedUnstalledPlanThatGoesFarEnough) {
  StepOutput out;
  out.mode = StepMode::kSolved;
  out.trajectory = vertical_move(Vec3(0, 0, -30), -40, 1.5, 0.5);  // 10 m up
  ASSERT_FALSE(out.trajectory.empty());
  EXPECT_TRUE(plan_moves_off(out, 2.0));
  EXPECT_FALSE(plan_moves_off(out, 10.5));
  out.stalled = true;
  EXPECT_FALSE(plan_moves_off(out, 2.0));
  out.stalled = false;
  out.mode = StepMode::kKeptPrevious;
  EXPECT_FALSE(plan_moves_off(out, 2.0));
  out.mode = StepMode::kBraking;
  EXPECT_FALSE(plan_moves_off(out, 2.0));
}

}  // namespace
}  // namespace ofn::rh
