// Stops and heading turns flown by the controller, with the shipped
// settings (config/controller.yaml: gains, adaptation and its hold below
// path_heading.min_speed, the path heading's rate and acceleration limits,
// the yaw sweep widening when slow), and the simulated airframe. Eq. 8's
// forward-speed rule holds for the true speed within the benchmarks' 2 %
// (6 cm/s at 10 ft/s): the stop of braking.hpp (the RH optimiser brakes with
// it and the controller falls back to it) must not drift back, and a heading
// turn during a sideways stop must not unsettle the controller.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>

#include "ofn/common/braking.hpp"
#include "ofn/common/config.hpp"
#include "ofn/controller/controller_service.hpp"
#include "ofn/controller/heading_reference.hpp"
#include "ofn/controller/neural_adaptation.hpp"
#include "ofn/controller/trajectory_controller.hpp"
#include "ofn/vehicle_sim/disturbances.hpp"

namespace ofn::control {
namespace {

constexpr double kSpeedLimit = 3.048;                   // m/s, 10 ft/s
constexpr double kBraking = 0.8 * 1.6 * 0.3048;         // m/s^2: 0.8 of 1.6 ft/s^2
constexpr double kAllowedReverse = 0.02 * kSpeedLimit;  // m/s
constexpr double kClearance = 20 * 0.3048;              // m, R_s

ControllerConfig shipped_config() {
  auto reader = YamlReader::load_file(std::string(OFN_SOURCE_DIR) + "/config/controller.yaml");
  return load_controller_config(reader);
}

struct StopFlight {
  Vec3 velocity = Vec3(kSpeedLimit, 0, 0);  // m/s, steady before the stop
  double heading = 0;                       // rad, the nose at the start
  double cruise = 15;                       // s before the stop begins
  double ramp_time = kStopRampTime;         // s of the stop's ease-out
  /// rad: the path heading turns to face this from 2 s before the stop on
  /// (else it keeps `heading`).
  std::optional<double> face;
  /// m/s^2 along the velocity with which the reference speeds up over the
  /// last kSpeedUpTime before the stop (reaching `velocity` as it begins).
  double speeding_up = 0;
  double onset_time = kStopOnsetTime;  // s of the stop's build-up
};

constexpr double kSpeedUpTime = 1.5;  // s

struct FlownVelocity {
  double least_along = 0;     // m/s: least velocity along the stop, from the stop on
  double largest_across = 0;  // m/s: largest horizontal velocity across it, from 2 s before
};

/// The flight: steady at `velocity`, then the stop of braking.hpp; the yaw
/// reference as the controller service makes it (path heading plus sweep,
/// rates fed forward), adaptation held when slow.
FlownVelocity fly(const ControllerConfig& config, const StopFlight& flight) {
  vehicle::SimulatedVehicle sim(config.nominal, Vec3::Zero(), Disturbances{}, 0.0);
  const Vec3 start_position(0, 0, -40);
  const Vec3 speed_up = flight.velocity.normalized() * flight.speeding_up;
  const Vec3 cruise_velocity = flight.velocity - kSpeedUpTime * speed_up;
  const double speed_up_from = flight.cruise - kSpeedUpTime;
  // The reference before the stop: steady, then speeding up.
  auto before = [&](double t, Reference* ref) {
    const double u = std::max(0.0, t - speed_up_from);
    ref->position = start_position + cruise_velocity * t + 0.5 * u * u * speed_up;
    ref->velocity = cruise_velocity + u * speed_up;
    ref->acceleration = t >= speed_up_from ? speed_up : Vec3(Vec3::Zero());
  };
  const auto trim = vehicle::trim(sim.model(), cruise_velocity, flight.heading);
  vehicle::RotorcraftState start = trim.state;
  start.position = start_position;
  sim.reset(start, 0.0);
  sim.set_command(trim.controls);
  TrajectoryController controller(config.nominal, config.gains,
                                  make_adaptive_element(config.adaptive));
  PathHeadingFilter path_heading(config.heading);
  path_heading.reset(flight.heading);
  YawSweepGenerator sweep(config.sweep);
  const double dt = 1.0 / config.rate;
  Reference stop_start;
  before(flight.cruise, &stop_start);
  const StopProfile stop =
      stop_from(stop_start.position, stop_start.velocity, stop_start.acceleration, kBraking,
                flight.ramp_time, flight.onset_time);
  const Vec3 along = stop.direction();
  const Vec3 across = Vec3::UnitZ().cross(along);
  const double turn_from = flight.cruise - 2.0;
  FlownVelocity flown;
  flown.least_along = flight.velocity.norm();
  for (int k = 0; k < static_cast<int>((flight.cruise + stop.stop_time + 10.0) / dt); ++k) {
    const double t = k * dt;
    const vehicle::NavSample nav = sim.measure();
    Reference ref;
    if (t < flight.cruise) {
      before(t, &ref);
    } else {
      ref.position = stop.position(t - flight.cruise);
      ref.velocity = stop.velocity_at(t - flight.cruise);
      ref.acceleration = stop.acceleration_at(t - flight.cruise);
    }
    std::optional<Vec3> facing = Vec3(std::cos(flight.heading), std::sin(flight.heading), 0.0);
    if (flight.face && t >= turn_from)
      facing = Vec3(std::cos(*flight.face), std::sin(*flight.face), 0.0);
    ref.yaw = path_heading.update(facing, dt);
    ref.yaw_rate = path_heading.turn_rate();
    const double horizontal = std::hypot(nav.velocity.x(), nav.velocity.y());
    double sweep_rate = 0;
    ref.yaw = wrap_angle(ref.yaw + sweep.update_at_speed(horizontal, config.heading.min_speed,
                                                         SweepCoverage{kClearance, kBraking}, dt,
                                                         &sweep_rate));
    ref.yaw_rate += sweep_rate;
    const VehicleEstimate x{nav.position, nav.velocity, nav.attitude, nav.body_rates};
    const ControlOutput out = controller.step(ref, x, dt);
    EXPECT_TRUE(out.valid);
    sim.set_command(out.controls);
    for (int i = 0; i < 4; ++i) sim.step(dt / 4);
    const Vec3 v = sim.model().state().velocity;
    if (t >= flight.cruise) flown.least_along = std::min(flown.least_along, v.dot(along));
    if (t >= turn_from)
      flown.largest_across = std::max(flown.largest_across, std::abs(v.dot(across)));
  }
  return flown;
}

TEST(StopFlown, NoStopDriftsBackBeyondTwoPercentOfTheSpeedLimit) {
  const ControllerConfig config = shipped_config();
  ASSERT_TRUE(config.sweep.enabled);
  ASSERT_TRUE(config.adaptive.enabled);
  int flown = 0;
  for (double speed : {kSpeedLimit, 1.5, 0.6})
    for (double heading : {0.0, 0.6, 1.1})
      for (double cruise : {15.0, 16.25, 17.5, 18.75}) {  // a quarter sweep period apart
        StopFlight flight;
        flight.velocity = Vec3(speed, 0, 0);
        flight.heading = heading;
        flight.cruise = cruise;
        EXPECT_GT(fly(config, flight).least_along, -kAllowedReverse)
            << "from " << speed << " m/s, nose " << heading << " rad off, stop at t = " << cruise;
        ++flown;
      }
  EXPECT_EQ(flown, 36);
}

// The least velocity along the stop over stops begun while the reference
// speeds up, from 0.45-1 m/s, with the nose along and 80 deg off the
// stop, at four sweep phases.
double least_along_after_speeding_up(const ControllerConfig& config, double onset_time) {
  double least = 1e9;
  for (double speed : {0.45, 1.0})
    for (double heading : {0.0, 1.4})
      for (double cruise : {15.0, 16.25, 17.5, 18.75}) {
        StopFlight flight;
        flight.velocity = Vec3(speed, 0, 0);
        flight.heading = heading;
        flight.cruise = cruise;
        flight.speeding_up = 0.3;
        flight.onset_time = onset_time;
        least = std::min(least, fly(config, flight).least_along);
      }
  return least;
}

TEST(StopFlown, AStopBegunWhileSpeedingUpBuildsUpAndDoesNotDriftBack) {
  // The RH optimiser brakes, and the controller falls back to the stop,
  // from whatever the reference does: here it was still speeding up at
  // 0.3 m/s^2. The stop starts from that acceleration (2.1-3.1 cm/s back at
  // worst with the 0.6 s onset).
  EXPECT_GT(least_along_after_speeding_up(shipped_config(), kStopOnsetTime), -kAllowedReverse);
}

TEST(StopFlown, AStopSteppedFromSpeedingUpToBrakingDriftsBack) {
  // What the onset is for: stepped from +0.3 to -0.39 m/s^2, the vehicle
  // overshoots the reference, brakes harder to catch up, and drifts back by
  // 13 cm/s (random dense field 18).
  ASSERT_GT(kStopOnsetTime, 0.0);
  EXPECT_LT(least_along_after_speeding_up(shipped_config(), 0.0), -kAllowedReverse);
}

TEST(StopFlown, AQuickEaseOutDriftsBack) {
  // What the ease-out is for: from a slow cruise with the sweep wide, a stop
  // that eases out over 0.8 s drifts back by more than the rule allows.
  ASSERT_GT(kStopRampTime, 0.8);
  const ControllerConfig config = shipped_config();
  double worst = 0;
  for (double heading : {0.0, 1.1}) {
    StopFlight flight;
    flight.velocity = Vec3(0.6, 0, 0);
    flight.heading = heading;
    flight.cruise = 16.25;
    flight.ramp_time = 0.8;
    worst = std::min(worst, fly(config, flight).least_along);
  }
  EXPECT_LT(worst, -kAllowedReverse);
}

/// Largest velocity across a stop from a sideways cruise east at 2.5 m/s,
/// the heading turning to face east from 2 s before the stop, over starting
/// headings and sweep phases.
double largest_across_a_turning_stop(const ControllerConfig& config) {
  double largest = 0;
  for (double heading : {0.0, 0.5, 1.0})
    for (double cruise : {15.0, 16.25, 17.5, 18.75}) {
      StopFlight flight;
      flight.velocity = Vec3(0, 2.5, 0);
      flight.heading = heading;
      flight.cruise = cruise;
      flight.face = kPi / 2;
      largest = std::max(largest, fly(config, flight).largest_across);
    }
  return largest;
}

TEST(StopFlown, AHeadingTurnDuringASidewaysStopStaysSteady) {
  // Sideways along the course, the velocity across the stop is the forward
  // speed of Eq. 8. With the shipped heading limits the swing is 0.12 m/s
  // at worst (a 33 deg turn under the sweep, just before the stop): twice
  // the 2 % rule; docs/LIMITATIONS.md. The bound here is the one that tells
  // a steady turn from the stepped one below.
  const ControllerConfig config = shipped_config();
  EXPECT_LT(largest_across_a_turning_stop(config), 0.15);
}

TEST(StopFlown, ASteppedTurnRateSwingsTheVelocityAcrossTheStop) {
  // What the heading's acceleration limit is for: with the turn rate
  // stepping to its limit at once, the same flights swing the velocity
  // across the stop far more (in simulation the inner adaptive element,
  // learning from the transient, diverged to metres per second).
  ControllerConfig config = shipped_config();
  config.heading.max_accel = 1e6;
  EXPECT_GT(largest_across_a_turning_stop(config), 1.0);
}

}  // namespace
}  // namespace ofn::control
