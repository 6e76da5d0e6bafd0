// The airframe's own failsafe: the actuator-command watchdog takes over
// when commands stop, its stabiliser levels and slows the airframe without
// speeding it up and within the actuator limits, and it hands back on the
// next command.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "ofn/vehicle_sim/airframe_failsafe.hpp"
#include "ofn/vehicle_sim/rotorcraft_simulation.hpp"

namespace ofn::vehicle {
namespace {

constexpr double kDt = 1.0 / 400.0;  // the simulation's physics step
constexpr double kFeet = 0.3048;     // m
constexpr double kTimeout = 0.2;     // s, the configured default

/// A vehicle in trimmed flight at `velocity` (NED) with heading `yaw`,
/// commanded with its trim: the flight computer's last command.
RotorcraftSimulation trimmed(const Vec3& velocity, double yaw, const RotorcraftParams& p = {}) {
  RotorcraftSimulation model(p);
  const TrimResult t = trim(model, velocity, yaw);
  EXPECT_TRUE(t.converged);
  model.set_state(t.state);
  model.set_command(t.controls);
  return model;
}

/// The angle between the airframe's roll and pitch and the hover trim's.
double tilt_from_hover(const RotorcraftState& s, const RotorcraftParams& p) {
  const Vec3 hover = euler_from_quat(trim(RotorcraftModel(p), Vec3::Zero(), 0.0).state.attitude);
  const Vec3 e = euler_from_quat(s.attitude);
  return std::hypot(e.x() - hover.x(), e.y() - hover.y());
}

/// What a flight under the failsafe did, sampled every physics step.
struct Trace {
  double takeover_time = -1;     // s, the first step the stabiliser flew
  double max_speed = 0;          // m/s, from the takeover on
  double speed_at_takeover = 0;  // m/s
  double max_tilt_late = 0;      // rad from the hover attitude, over the last 2 s
  bool within_limits = true;     // every stabiliser command within the position limits
  Controls worst;                // a command beyond them, if any
};

/// Flies `model` for `seconds` with the last command at t = 0 and none
/// after, the failsafe fed every step.
Trace fly_unattended(RotorcraftSimulation& model, AirframeFailsafe& failsafe, double seconds) {
  Trace trace;
  const RotorcraftParams& p = model.params();
  failsafe.command_received(0.0);
  const int steps = static_cast<int>(std::lround(seconds / kDt));
  for (int i = 1; i <= steps; ++i) {
    const double t = i * kDt;
    if (const auto c = failsafe.update(t, model.state())) {
      if (trace.takeover_time < 0) {
        trace.takeover_time = t;
        trace.speed_at_takeover = model.state().velocity.norm();
      }
      const auto a = c->as_array(), lo = p.min_controls.as_array(), hi = p.max_controls.as_array();
      for (int k = 0; k < 4; ++k)
        if (a[k] < lo[k] || a[k] > hi[k]) {
          trace.within_limits = false;
          trace.worst = *c;
        }
      model.set_command(*c);
    }
    model.step(kDt);
    if (trace.takeover_time >= 0)
      trace.max_speed = std::max(trace.max_speed, model.state().velocity.norm());
    if (t > seconds - 2.0)
      trace.max_tilt_late = std::max(trace.max_tilt_late, tilt_from_hover(model.state(), p));
  }
  return trace;
}

TEST(AirframeFailsafe, TakesOverOnceCommandsAreOlderThanTheTimeout) {
  RotorcraftSimulation model = trimmed(Vec3::Zero(), 0.0);
  AirframeFailsafe failsafe(model.params(), kTimeout);
  EXPECT_TRUE(failsafe.enabled());
  EXPECT_FALSE(failsafe.armed());
  failsafe.command_received(1.0);
  EXPECT_TRUE(failsafe.armed());
  // Commands every 10 ms for a second: it never acts.
  for (int i = 0; i <= 100; ++i) {
    const double t = 1.0 + 0.01 * i;
    failsafe.command_received(t);
    EXPECT_FALSE(failsafe.update(t + 0.005, model.state())) << "at " << t;
  }
  EXPECT_EQ(failsafe.takeovers(), 0);
  // The last at t = 2.0: still the flight computer's a step before 2.2,
  // the stabiliser's a step after.
  EXPECT_FALSE(failsafe.update(2.0 + kTimeout - kDt, model.state()));
  EXPECT_FALSE(failsafe.engaged());
  EXPECT_TRUE(failsafe.update(2.0 + kTimeout + kDt, model.state()));
  EXPECT_TRUE(failsafe.engaged());
  EXPECT_EQ(failsafe.takeovers(), 1);
  EXPECT_NEAR(failsafe.engaged_since(), 2.0 + kTimeout + kDt, 1e-12);
  // Once engaged it keeps flying, and counts the takeover once.
  for (int i = 1; i <= 400; ++i) EXPECT_TRUE(failsafe.update(2.2 + i * kDt, model.state()));
  EXPECT_EQ(failsafe.takeovers(), 1);
}

TEST(AirframeFailsafe, HandsBackOnTheNextCommandAndCountsEachTakeover) {
  RotorcraftSimulation model = trimmed(Vec3::Zero(), 0.0);
  AirframeFailsafe failsafe(model.params(), kTimeout);
  failsafe.command_received(0.0);
  ASSERT_TRUE(failsafe.update(0.5, model.state()));
  EXPECT_TRUE(failsafe.command_received(0.6));  // ends the takeover
  EXPECT_FALSE(failsafe.engaged());
  EXPECT_FALSE(failsafe.update(0.6, model.state()));
  EXPECT_FALSE(failsafe.command_received(0.7));  // not engaged: nothing handed back
  EXPECT_FALSE(failsafe.update(0.85, model.state()));
  EXPECT_TRUE(failsafe.update(0.95, model.state()));
  EXPECT_EQ(failsafe.takeovers(), 2);
  EXPECT_TRUE(failsafe.command_received(1.1));
  EXPECT_EQ(failsafe.takeovers(), 2);
}

TEST(AirframeFailsafe, NeverActsBeforeTheFirstCommandOrWhenOff) {
  RotorcraftSimulation model = trimmed(Vec3::Zero(), 0.0);
  AirframeFailsafe unarmed(model.params(), kTimeout);
  for (double t = 0; t < 10.0; t += 0.1) EXPECT_FALSE(unarmed.update(t, model.state()));
  AirframeFailsafe off(model.params(), 0.0);
  EXPECT_FALSE(off.enabled());
  off.command_received(0.0);
  for (double t = 0; t < 10.0; t += 0.1) EXPECT_FALSE(off.update(t, model.state()));
  EXPECT_EQ(off.takeovers(), 0);
}

TEST(AirframeFailsafe, RefusesANegativeOrNonFiniteTimeout) {
  const RotorcraftParams p;
  EXPECT_THROW(AirframeFailsafe(p, -0.1), std::invalid_argument);
  EXPECT_THROW(AirframeFailsafe(p, std::nan("")), std::invalid_argument);
  EXPECT_THROW(AirframeFailsafe(p, INFINITY), std::invalid_argument);
}

// The benchmark cruise, 10 ft/s, in four directions against the heading:
// the stabiliser brings it to a level hover and never speeds it up.
TEST(HoverStabiliser, LevelsAndSlowsAVehicleAt10FtPerSecondWithoutSpeedingItUp) {
  const double speed = 10.0 * kFeet;
  for (const double heading_deg : {0.0, 60.0, -135.0}) {
    for (const double course_deg : {0.0, 90.0, 180.0, -45.0}) {
      const double yaw = deg2rad(heading_deg), course = yaw + deg2rad(course_deg);
      const Vec3 velocity = speed * Vec3(std::cos(course), std::sin(course), 0.0);
      RotorcraftSimulation model = trimmed(velocity, yaw);
      AirframeFailsafe failsafe(model.params(), kTimeout);
      const Trace trace = fly_unattended(model, failsafe, 15.0);
      SCOPED_TRACE(testing::Message()
                   << "heading " << heading_deg << " deg, course " << course_deg << " deg off it");
      EXPECT_NEAR(trace.takeover_time, kTimeout + kDt, 1e-9);
      EXPECT_EQ(failsafe.takeovers(), 1);
      // Never faster than it flew when the commands stopped.
      EXPECT_LE(trace.max_speed, trace.speed_at_takeover + 1e-3);
      EXPECT_NEAR(trace.speed_at_takeover, speed, 0.01);
      // A hover: slow, level, the heading held.
      const RotorcraftState& s = model.state();
      EXPECT_LT(s.velocity.norm(), 0.1) << "velocity " << s.velocity.transpose();
      EXPECT_LT(rad2deg(trace.max_tilt_late), 1.0);
      EXPECT_LT(rad2deg(std::abs(wrap_angle(euler_from_quat(s.attitude).z() - yaw))), 2.0);
      EXPECT_LT(std::abs(s.position.z()), 1.0) << "height held";
      EXPECT_TRUE(trace.within_limits)
          << "command " << trace.worst.collective << " " << trace.worst.lon_cyclic << " "
          << trace.worst.lat_cyclic << " " << trace.worst.pedal;
    }
  }
}

// Taken over tilted, turning and climbing (the flight computer stopped in
// a manoeuvre): it levels the airframe and slows it to a hover, its
// commands within the actuator limits throughout.
TEST(HoverStabiliser, RecoversATiltedTurningVehicleWithinTheActuatorLimits) {
  RotorcraftSimulation model = trimmed(Vec3(3.048, 1.0, -0.5), 0.3);
  RotorcraftState s = model.state();
  s.attitude = quat_from_euler(deg2rad(15), deg2rad(-10), 0.3);
  s.body_rates = Vec3(0.3, -0.2, 0.4);
  model.set_state(s);
  Controls last = model.command();
  last.lat_cyclic = model.params().max_controls.lat_cyclic;  // at its stop
  last.pedal = 0.3;
  model.set_command(last);
  AirframeFailsafe failsafe(model.params(), kTimeout);
  const Trace trace = fly_unattended(model, failsafe, 20.0);
  EXPECT_TRUE(trace.within_limits);
  EXPECT_LT(model.state().velocity.norm(), 0.1);
  EXPECT_LT(rad2deg(trace.max_tilt_late), 1.0);
  // Speed gained before the attitude is caught stays small.
  EXPECT_LT(trace.max_speed, trace.speed_at_takeover + 1.0);
}

// An airframe heavier than the one the stabiliser was trimmed for (the
// scenario's variation): still a hover, a little lower.
TEST(HoverStabiliser, HoldsAHeavierAirframeNearItsHeight) {
  RotorcraftParams heavy;
  heavy.mass *= 1.2;
  RotorcraftSimulation model = trimmed(Vec3(3.048, 0.0, 0.0), 0.0, heavy);
  AirframeFailsafe failsafe(RotorcraftParams{}, kTimeout);
  const Trace trace = fly_unattended(model, failsafe, 30.0);
  EXPECT_LE(trace.max_speed, trace.speed_at_takeover + 1e-3);
  EXPECT_LT(model.state().velocity.norm(), 0.1);
  EXPECT_LT(std::abs(model.state().position.z()), 10.0);
}

TEST(HoverStabiliser, CentresOnTheHoverTrim) {
  const RotorcraftParams p;
  const HoverStabiliser stabiliser(p);
  const TrimResult t = trim(RotorcraftModel(p), Vec3::Zero(), 0.0);
  HoverStabiliser engaged = stabiliser;
  engaged.engage(t.state);
  const Controls c = engaged.command(t.state);
  EXPECT_NEAR(c.collective, t.controls.collective, 1e-9);
  EXPECT_NEAR(c.lon_cyclic, t.controls.lon_cyclic, 1e-9);
  EXPECT_NEAR(c.lat_cyclic, t.controls.lat_cyclic, 1e-9);
  EXPECT_NEAR(c.pedal, t.controls.pedal, 1e-9);
}

}  // namespace
}  // namespace ofn::vehicle
