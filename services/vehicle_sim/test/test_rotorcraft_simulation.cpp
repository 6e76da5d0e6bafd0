// The 6-DOF rotorcraft model flown by its simulation: trim as an
// equilibrium, control sense, actuator limits and inflow. The model's cases
// that need no simulation are in services/rotorcraft_model/test.

#include <gtest/gtest.h>

#include <cmath>

#include "ofn/rotorcraft_model/rotorcraft_model.hpp"
#include "ofn/vehicle_sim/rotorcraft_simulation.hpp"

namespace ofn::vehicle {
namespace {

constexpr double kPhysicsStep = 1.0 / 400.0;  // the simulation's physics step

/// Steps `model` for `seconds` at 400 Hz.
void fly(RotorcraftSimulation& model, double seconds) {
  const int steps = static_cast<int>(std::lround(seconds / kPhysicsStep));
  for (int i = 0; i < steps; ++i) model.step(kPhysicsStep);
}

/// A model at hover trim, commanded with the trim controls.
RotorcraftSimulation hovering(TrimResult* trim_out = nullptr) {
  RotorcraftSimulation model;
  const TrimResult t = trim(model, Vec3::Zero(), 0.0);
  model.set_state(t.state);
  model.set_command(t.controls);
  if (trim_out) *trim_out = t;
  return model;
}

double angle_between(const Quat& a, const Quat& b) {
  return a.angularDistance(b);
}

TEST(RotorcraftModel, HoverTrimConvergesToAnEquilibrium) {
  RotorcraftSimulation model;
  const TrimResult t = trim(model, Vec3::Zero(), 0.0);
  ASSERT_TRUE(t.converged) << "residual " << t.residual;
  EXPECT_LT(t.residual, 1e-6);

  model.set_state(t.state);
  model.set_command(t.controls);
  fly(model, 1.0);
  const RotorcraftState& s = model.state();
  EXPECT_LT((s.position - t.state.position).norm(), 0.05);
  EXPECT_LT(s.velocity.norm(), 0.05);
  EXPECT_LT(rad2deg(angle_between(s.attitude, t.state.attitude)), 0.5);
  EXPECT_TRUE(s.position.allFinite());
}

TEST(RotorcraftModel, HoverTrimThrustCarriesTheWeight) {
  TrimResult t;
  RotorcraftSimulation model = hovering(&t);
  model.step(kPhysicsStep);
  const auto& p = model.params();
  // Level hover: thrust equals weight to well within a percent.
  EXPECT_NEAR(model.loads().thrust, p.mass * kGravity, 0.01 * p.mass * kGravity);
  // A level attitude within a few degrees (tail-rotor side force needs some roll).
  const Vec3 e = euler_from_quat(t.state.attitude);
  EXPECT_LT(std::abs(rad2deg(e.x())), 5.0);
  EXPECT_LT(std::abs(rad2deg(e.y())), 5.0);
  EXPECT_NEAR(e.z(), 0.0, 1e-9);
}

TEST(RotorcraftModel, ForwardFlightTrimConvergesAndHolds) {
  RotorcraftSimulation model;
  const Vec3 velocity(3.048, 0.0, 0.0);  // 10 ft/s, the benchmark cruise speed
  const TrimResult t = trim(model, velocity, 0.0);
  ASSERT_TRUE(t.converged) << "residual " << t.residual;
  model.set_state(t.state);
  model.set_command(t.controls);
  fly(model, 1.0);
  const RotorcraftState& s = model.state();
  EXPECT_LT((s.velocity - velocity).norm(), 0.05);
  EXPECT_NEAR(s.velocity.norm(), velocity.norm(), 0.05);
  // It went the distance: 3.048 m north in 1 s.
  EXPECT_NEAR(s.position.x(), 3.048, 0.05);
  EXPECT_LT(rad2deg(angle_between(s.attitude, t.state.attitude)), 0.5);
}

TEST(RotorcraftModel, ForwardFlightTrimHoldsAtAnotherHeading) {
  RotorcraftSimulation model;
  const double yaw = deg2rad(60);
  const Vec3 velocity = 3.048 * Vec3(std::cos(yaw), std::sin(yaw), 0.0);
  const TrimResult t = trim(model, velocity, yaw);
  ASSERT_TRUE(t.converged) << "residual " << t.residual;
  EXPECT_NEAR(euler_from_quat(t.state.attitude).z(), yaw, 1e-9);
  model.set_state(t.state);
  model.set_command(t.controls);
  fly(model, 1.0);
  EXPECT_LT((model.state().velocity - velocity).norm(), 0.05);
}

TEST(RotorcraftModel, ExtraCollectiveFromHoverClimbs) {
  TrimResult t;
  RotorcraftSimulation model = hovering(&t);
  Controls c = t.controls;
  c.collective += 0.03;
  model.set_command(c);
  fly(model, 0.5);
  EXPECT_LT(model.acceleration().z(), -0.1);  // accelerating up (NED down is +)
  fly(model, 0.5);
  EXPECT_LT(model.state().velocity.z(), -0.1);  // climbing
  EXPECT_GT(model.loads().thrust, model.params().mass * kGravity);
}

TEST(RotorcraftModel, LessCollectiveFromHoverDescends) {
  TrimResult t;
  RotorcraftSimulation model = hovering(&t);
  Controls c = t.controls;
  c.collective -= 0.03;
  model.set_command(c);
  fly(model, 1.0);
  EXPECT_GT(model.state().velocity.z(), 0.1);
}

TEST(RotorcraftModel, ForwardCyclicPitchesNoseDownAndAcceleratesNorth) {
  TrimResult t;
  RotorcraftSimulation model = hovering(&t);
  Controls c = t.controls;
  c.lon_cyclic += 0.03;
  model.set_command(c);
  fly(model, 0.3);
  EXPECT_LT(model.state().body_rates.y(), 0.0) << "pitch rate q";
  const double pitch_03 = euler_from_quat(model.state().attitude).y();
  EXPECT_LT(pitch_03, euler_from_quat(t.state.attitude).y());
  fly(model, 1.7);
  EXPECT_GT(model.state().velocity.x(), 0.1);
  EXPECT_GT(model.state().position.x(), 0.0);
}

TEST(RotorcraftModel, AftCyclicPitchesNoseUp) {
  TrimResult t;
  RotorcraftSimulation model = hovering(&t);
  Controls c = t.controls;
  c.lon_cyclic -= 0.03;
  model.set_command(c);
  fly(model, 0.3);
  EXPECT_GT(model.state().body_rates.y(), 0.0);
  fly(model, 1.7);
  EXPECT_LT(model.state().velocity.x(), -0.1);
}

TEST(RotorcraftModel, RightCyclicRollsRight) {
  TrimResult t;
  RotorcraftSimulation model = hovering(&t);
  Controls c = t.controls;
  c.lat_cyclic += 0.03;
  model.set_command(c);
  fly(model, 0.3);
  EXPECT_GT(model.state().body_rates.x(), 0.0) << "roll rate p";
  EXPECT_GT(euler_from_quat(model.state().attitude).x(), euler_from_quat(t.state.attitude).x());
  fly(model, 1.7);
  EXPECT_GT(model.state().velocity.y(), 0.1);  // drifts east
}

TEST(RotorcraftModel, RightPedalYawsNoseRight) {
  TrimResult t;
  RotorcraftSimulation model = hovering(&t);
  Controls c = t.controls;
  c.pedal += 0.05;
  model.set_command(c);
  fly(model, 0.5);
  EXPECT_GT(model.state().body_rates.z(), 0.0) << "yaw rate r";
  EXPECT_GT(euler_from_quat(model.state().attitude).z(), 0.0);

  RotorcraftSimulation left = hovering();
  c = t.controls;
  c.pedal -= 0.05;
  left.set_command(c);
  fly(left, 0.5);
  EXPECT_LT(left.state().body_rates.z(), 0.0);
}

TEST(RotorcraftModel, CommandBeyondLimitsIsClamped) {
  RotorcraftSimulation model;
  const auto& p = model.params();
  model.set_command({1.0, 1.0, -1.0, 5.0});
  EXPECT_DOUBLE_EQ(model.command().collective, p.max_controls.collective);
  EXPECT_DOUBLE_EQ(model.command().lon_cyclic, p.max_controls.lon_cyclic);
  EXPECT_DOUBLE_EQ(model.command().lat_cyclic, p.min_controls.lat_cyclic);
  EXPECT_DOUBLE_EQ(model.command().pedal, p.max_controls.pedal);
  model.set_command({-1.0, -1.0, 1.0, -5.0});
  EXPECT_DOUBLE_EQ(model.command().collective, p.min_controls.collective);
  EXPECT_DOUBLE_EQ(model.command().lon_cyclic, p.min_controls.lon_cyclic);
  EXPECT_DOUBLE_EQ(model.command().lat_cyclic, p.max_controls.lat_cyclic);
  EXPECT_DOUBLE_EQ(model.command().pedal, p.min_controls.pedal);
  // Within the limits a command passes unchanged.
  model.set_command({0.1, 0.02, -0.03, 0.05});
  EXPECT_DOUBLE_EQ(model.command().collective, 0.1);
  EXPECT_DOUBLE_EQ(model.command().lon_cyclic, 0.02);
  EXPECT_DOUBLE_EQ(model.command().lat_cyclic, -0.03);
  EXPECT_DOUBLE_EQ(model.command().pedal, 0.05);
}

TEST(RotorcraftModel, ActuatorsNeverLeaveTheirLimits) {
  TrimResult t;
  RotorcraftSimulation model = hovering(&t);
  const auto& p = model.params();
  model.set_command({10.0, -10.0, 10.0, -10.0});
  for (int i = 0; i < 200; ++i) {
    model.step(kPhysicsStep);
    const auto a = model.state().actuators.as_array();
    const auto lo = p.min_controls.as_array(), hi = p.max_controls.as_array();
    for (int k = 0; k < 4; ++k) {
      ASSERT_GE(a[k], lo[k] - 1e-12) << "channel " << k << " step " << i;
      ASSERT_LE(a[k], hi[k] + 1e-12) << "channel " << k << " step " << i;
    }
  }
  // Held at the limit, the collective has reached it after 0.5 s.
  EXPECT_NEAR(model.state().actuators.collective, p.max_controls.collective, 1e-6);
}

TEST(RotorcraftModel, ServoRateLimitBoundsActuatorMotion) {
  TrimResult t;
  RotorcraftSimulation model = hovering(&t);
  const auto& p = model.params();
  Controls c = t.controls;
  c.lon_cyclic = p.max_controls.lon_cyclic;
  model.set_command(c);
  const double before = model.state().actuators.lon_cyclic;
  fly(model, 0.02);
  const double moved = model.state().actuators.lon_cyclic - before;
  EXPECT_GT(moved, 0.0);
  EXPECT_LE(moved, p.actuator_rate.lon_cyclic * 0.02 + 1e-9);
}

TEST(RotorcraftModel, SteadyHoverInflowMatchesMomentumTheory) {
  const RotorcraftModel model;
  const auto& p = model.params();
  for (double c : {0.08, 0.12, 0.16, 0.2}) {
    const double vi = model.steady_induced_velocity(c, Vec3::Zero());
    const double thrust = model.thrust(c, vi, Vec3::Zero());
    ASSERT_GT(thrust, 0.0);
    const double momentum = std::sqrt(thrust / (2.0 * p.air_density * p.disk_area()));
    EXPECT_NEAR(vi, momentum, 0.01 * momentum) << "collective " << c;
  }
  // At the hover trim the inflow is that of the vehicle's weight.
  TrimResult t;
  hovering(&t);
  const double weight_inflow = std::sqrt(p.mass * kGravity / (2.0 * p.air_density * p.disk_area()));
  EXPECT_NEAR(t.state.induced_velocity, weight_inflow, 0.01 * weight_inflow);
}

TEST(RotorcraftModel, InflowSettlesToItsSteadyValue) {
  TrimResult t;
  RotorcraftSimulation model = hovering(&t);
  RotorcraftState s = model.state();
  s.induced_velocity = 0.0;  // inflow not yet built up
  model.set_state(s);
  fly(model, 1.0);  // ten time constants
  EXPECT_NEAR(model.state().induced_velocity, t.state.induced_velocity,
              0.02 * t.state.induced_velocity);
}

}  // namespace
}  // namespace ofn::vehicle
