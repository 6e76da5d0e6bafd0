// The trajectory controller in closed loop with the rotorcraft model, and its
// behaviour on bad inputs.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <utility>
#include <vector>

#include "ofn/common/braking.hpp"
#include "ofn/controller/trajectory_controller.hpp"
#include "ofn/rotorcraft_model/rotorcraft_model.hpp"
#include "ofn/vehicle_sim/rotorcraft_simulation.hpp"

namespace ofn::control {
namespace {

using vehicle::Controls;
using vehicle::RotorcraftModel;
using vehicle::RotorcraftParams;
using vehicle::RotorcraftSimulation;

constexpr double kControlDt = 0.01;    // 100 Hz control loop
constexpr int kPhysicsPerControl = 4;  // 400 Hz physics
constexpr double kNaNInput = std::numeric_limits<double>::quiet_NaN();
constexpr double kInfInput = std::numeric_limits<double>::infinity();

VehicleEstimate estimate_of(const vehicle::RotorcraftState& s) {
  VehicleEstimate x;
  x.position = s.position;
  x.velocity = s.velocity;
  x.attitude = s.attitude;
  x.body_rates = s.body_rates;
  return x;
}

bool controls_within_limits(const Controls& c, const RotorcraftParams& p) {
  const auto v = c.as_array(), lo = p.min_controls.as_array(), hi = p.max_controls.as_array();
  for (int i = 0; i < 4; ++i)
    if (!std::isfinite(v[i]) || v[i] < lo[i] || v[i] > hi[i]) return false;
  return true;
}

/// Vehicle (nominal parameters) starting in hover trim at the origin, flown
/// by the controller with the same nominal parameters.
class ClosedLoop {
 public:
  /// `max_speed`, `max_vertical_speed` > 0 turn the speed governor on.
  explicit ClosedLoop(double max_speed = 0, double max_vertical_speed = 0,
                      ControllerGains gains = {})
      : controller_(RotorcraftParams{}, gains) {
    controller_.set_speed_limits(max_speed, max_vertical_speed);
    const auto t = vehicle::trim(model_, Vec3::Zero(), 0.0);
    EXPECT_TRUE(t.converged);
    model_.set_state(t.state);
    model_.set_command(t.controls);
  }

  /// One control period: controller step, then four physics steps.
  ControlOutput step(const Reference& ref) {
    const ControlOutput out = controller_.step(ref, estimate_of(model_.state()), kControlDt);
    model_.set_command(out.controls);
    for (int i = 0; i < kPhysicsPerControl; ++i) model_.step(kControlDt / kPhysicsPerControl);
    return out;
  }

  const vehicle::RotorcraftState& state() const { return model_.state(); }
  const RotorcraftSimulation& model() const { return model_; }
  /// Changes the vehicle's velocity by `dv` (world), as a push the
  /// controller is not told of.
  void push(const Vec3& dv) {
    vehicle::RotorcraftState x = model_.state();
    x.velocity += dv;
    model_.set_state(x);
  }

 private:
  RotorcraftSimulation model_;
  TrajectoryController controller_;
};

/// Outcome of a reference step along one world axis.
struct StepResponse {
  double overshoot = 0;        // m beyond the target, along the step
  double settling_time = 1e9;  // s after which |error| stays within the band
  double final_error = 0;      // m
  double max_off_axis = 0;     // m, largest deviation on the other axes
  bool all_valid = true;
  bool all_within_limits = true;
};

StepResponse fly_step(int axis, double size, double band, double duration) {
  ClosedLoop loop;
  Reference ref;
  ref.position[axis] = size;
  StepResponse r;
  const int steps = static_cast<int>(std::lround(duration / kControlDt));
  double last_outside = 0.0;
  for (int i = 0; i < steps; ++i) {
    const ControlOutput out = loop.step(ref);
    r.all_valid = r.all_valid && out.valid;
    r.all_within_limits =
        r.all_within_limits && controls_within_limits(out.controls, loop.model().params());
    const double t = (i + 1) * kControlDt;
    const Vec3& pos = loop.state().position;
    const double along = pos[axis] * (size > 0 ? 1.0 : -1.0);
    r.overshoot = std::max(r.overshoot, along - std::abs(size));
    const double error = std::abs(pos[axis] - size);
    if (error > band) last_outside = t;
    for (int k = 0; k < 3; ++k)
      if (k != axis) r.max_off_axis = std::max(r.max_off_axis, std::abs(pos[k]));
    r.final_error = error;
  }
  r.settling_time = last_outside;
  return r;
}

TEST(TrajectoryController, HoldsHoverAtOriginFor20s) {
  ClosedLoop loop;
  const Reference ref;  // origin, level, facing north
  for (int i = 0; i < 2000; ++i) {
    const ControlOutput out = loop.step(ref);
    ASSERT_TRUE(out.valid) << "step " << i;
  }
  EXPECT_LT(loop.state().position.norm(), 0.1);
  EXPECT_LT(loop.state().velocity.norm(), 0.1);
  EXPECT_LT(std::abs(euler_from_quat(loop.state().attitude).z()), deg2rad(2.0));
}

// Stated performance of the outer loop for a 5 m horizontal position step
// from hover (no feed-forward): the error falls into and stays within 10 %
// of the step (0.5 m) within 15 s, and overshoot stays below 30 % (1.5 m).
TEST(TrajectoryController, NorthStepSettlesWithin15sWithOvershootBelow30Percent) {
  const StepResponse r = fly_step(0, 5.0, 0.5, 25.0);
  EXPECT_TRUE(r.all_valid);
  EXPECT_TRUE(r.all_within_limits);
  EXPECT_LT(r.settling_time, 15.0);
  EXPECT_LT(r.overshoot, 1.5);
  EXPECT_LT(r.final_error, 0.5);
  EXPECT_LT(r.max_off_axis, 1.0);  // the step stays on its axis
}

TEST(TrajectoryController, EastStepSettlesWithin15sWithOvershootBelow30Percent) {
  const StepResponse r = fly_step(1, 5.0, 0.5, 25.0);
  EXPECT_TRUE(r.all_valid);
  EXPECT_TRUE(r.all_within_limits);
  EXPECT_LT(r.settling_time, 15.0);
  EXPECT_LT(r.overshoot, 1.5);
  EXPECT_LT(r.final_error, 0.5);
  EXPECT_LT(r.max_off_axis, 1.0);
}

TEST(TrajectoryController, SouthWestStepsAreSymmetric) {
  const StepResponse south = fly_step(0, -5.0, 0.5, 25.0);
  EXPECT_LT(south.settling_time, 15.0);
  EXPECT_LT(south.overshoot, 1.5);
  const StepResponse west = fly_step(1, -5.0, 0.5, 25.0);
  EXPECT_LT(west.settling_time, 15.0);
  EXPECT_LT(west.overshoot, 1.5);
}

// Stated performance for a 3 m climb step (reference down = -3 m): overshoot
// below 30 % (0.9 m), and settled within 10 % (0.3 m) of the target within
// 10 s.
TEST(TrajectoryController, ClimbStepOvershootBelow30Percent) {
  const StepResponse r = fly_step(2, -3.0, 0.3, 20.0);
  EXPECT_TRUE(r.all_valid);
  EXPECT_TRUE(r.all_within_limits);
  EXPECT_LT(r.overshoot, 0.9);
  EXPECT_LT(r.final_error, 0.3);
  EXPECT_LT(r.max_off_axis, 1.0);
}

TEST(TrajectoryController, ClimbStepSettlesWithin10s) {
  const StepResponse r = fly_step(2, -3.0, 0.3, 20.0);
  EXPECT_LT(r.settling_time, 10.0);
}

TEST(TrajectoryController, FollowsAConstantVelocityReferenceWithFeedForward) {
  ClosedLoop loop;
  // Ramp the reference up to 3 m/s north at 0.5 m/s^2, then cruise.
  Reference ref;
  double s = 0, v = 0;
  double max_error_cruise = 0;
  for (int i = 0; i < 3000; ++i) {
    const double a = v < 3.0 ? 0.5 : 0.0;
    v = std::min(3.0, v + a * kControlDt);
    s += v * kControlDt;
    ref.position = Vec3(s, 0, 0);
    ref.velocity = Vec3(v, 0, 0);
    ref.acceleration = Vec3(a, 0, 0);
    ASSERT_TRUE(loop.step(ref).valid);
    if (i > 2000)
      max_error_cruise = std::max(max_error_cruise, (ref.position - loop.state().position).norm());
  }
  EXPECT_LT(max_error_cruise, 1.0);
  EXPECT_NEAR(loop.state().velocity.x(), 3.0, 0.2);
}

TEST(TrajectoryController, YawSweepInCruiseBarelyMovesTheSpeed) {
  // The scanner's yaw sweep (20 deg either way at 0.2 Hz) turns the tilted
  // disk about the vertical. Unless that turn is fed forward as body rates,
  // the attitude lags it and the flown speed swings with the yaw rate, which
  // is what the cruise's speed reserve has to cover.
  ClosedLoop loop;
  Reference ref;
  const double cruise = 3.0, amplitude = deg2rad(20), w = 2.0 * kPi * 0.2;
  double s = 0, v = 0, slowest = 1e9, fastest = 0;
  for (int i = 0; i < 6000; ++i) {
    const double t = i * kControlDt;
    const double a = v < cruise ? 0.5 : 0.0;
    v = std::min(cruise, v + a * kControlDt);
    s += v * kControlDt;
    ref.position = Vec3(s, 0, 0);
    ref.velocity = Vec3(v, 0, 0);
    ref.acceleration = Vec3(a, 0, 0);
    ref.yaw = amplitude * std::sin(w * t);
    ref.yaw_rate = amplitude * w * std::cos(w * t);
    ASSERT_TRUE(loop.step(ref).valid);
    if (t > 40.0) {
      const double speed = loop.state().velocity.norm();
      slowest = std::min(slowest, speed);
      fastest = std::max(fastest, speed);
    }
  }
  EXPECT_LT(fastest - slowest, 0.01 * cruise) << "speeds " << slowest << " to " << fastest;
}

/// Least north speed while the controller flies the stop of braking.hpp
/// (easing out over `ramp_time`) from a cruise 70 deg off north at the
/// benchmarks' limits (10 ft/s, 1.6 ft/s^2, braking at 0.8 of it).
double least_north_speed_in_a_stop(double ramp_time) {
  ClosedLoop loop;
  const double speed = 3.048, braking = 0.8 * 0.4877;
  const Vec3 cruise = speed * Vec3(std::cos(deg2rad(70)), std::sin(deg2rad(70)), 0.0);
  Reference ref;
  double least = 1e9;
  // Up to speed at 0.4 m/s^2 and 30 s of steady cruise before the stop.
  const double ramp_up = speed / 0.4, stop_begins = ramp_up + 30.0;
  std::optional<StopProfile> stop;
  for (int i = 0; i < static_cast<int>((stop_begins + 30.0) / kControlDt); ++i) {
    const double t = i * kControlDt;
    if (t < stop_begins) {
      const double v = std::min(t, ramp_up) * 0.4;
      const double s = t < ramp_up ? 0.2 * t * t : 0.2 * ramp_up * ramp_up + speed * (t - ramp_up);
      ref.position = cruise / speed * s;
      ref.velocity = cruise / speed * v;
      ref.acceleration = t < ramp_up ? Vec3(cruise / speed * 0.4) : Vec3(Vec3::Zero());
    } else {
      if (!stop) stop = stop_from(ref.position, ref.velocity, braking, ramp_time);
      ref.position = stop->position(t - stop_begins);
      ref.velocity = stop->velocity_at(t - stop_begins);
      ref.acceleration = stop->acceleration_at(t - stop_begins);
      least = std::min(least, loop.state().velocity.x());
    }
    // The scanner's yaw sweep, 20 deg either way at 0.2 Hz, fed forward.
    const double w = 2.0 * kPi * 0.2;
    ref.yaw = deg2rad(20) * std::sin(w * t);
    ref.yaw_rate = deg2rad(20) * w * std::cos(w * t);
    EXPECT_TRUE(loop.step(ref).valid);
  }
  return least;
}

TEST(TrajectoryController, AStopFromASidewaysCruiseDoesNotDriftBack) {
  // Eq. 8's forward-speed rule holds for the flown speed within 2 % of the
  // limit while the vehicle, whose tilt lags its command, flies the stop
  // that the optimiser brakes with and the controller falls back to.
  EXPECT_GT(least_north_speed_in_a_stop(kStopRampTime), -0.02 * 3.048);
}

/// At time t, a reference `lead` metres ahead along `direction` that
/// speeds up from rest at `accel` to `speed` and keeps it.
Reference speeding_up(const Vec3& direction, double speed, double accel, double lead, double t) {
  const double ramp = speed / accel;
  const double along =
      t < ramp ? 0.5 * accel * t * t : 0.5 * accel * ramp * ramp + speed * (t - ramp);
  Reference ref;
  ref.position = direction * (lead + along);
  ref.velocity = direction * std::min(speed, accel * t);
  ref.acceleration = direction * (t < ramp ? accel : 0.0);
  return ref;
}

/// The largest speed (3-D, and vertical) flown from a hover while the
/// reference, `lead` metres ahead along `direction`, speeds up from rest at
/// `accel` to `speed` and keeps it: with a lead, a plan restarted ahead of a
/// lagging vehicle (or a forged one), which the controller catches up with.
std::pair<double, double> fastest_chasing(const Vec3& direction, double speed, double accel,
                                          double lead, double max_speed,
                                          double max_vertical_speed) {
  ClosedLoop loop(max_speed, max_vertical_speed);
  double fastest = 0, fastest_vertical = 0;
  for (int i = 0; i < static_cast<int>(30.0 / kControlDt); ++i) {
    loop.step(speeding_up(direction, speed, accel, lead, i * kControlDt));
    fastest = std::max(fastest, loop.state().velocity.norm());
    fastest_vertical = std::max(fastest_vertical, std::abs(loop.state().velocity.z()));
  }
  return {fastest, fastest_vertical};
}

TEST(TrajectoryController, TheSpeedGovernorKeepsTheLimitWhileCatchingUpAPlanAhead) {
  // The reference starts 3 m ahead and speeds up to the limit: catching up,
  // the controller flies beyond the limit without the governor, and within
  // the 2 % of the benchmarks with it (governed at 1 %).
  const double limit = 3.048, vertical_limit = 1.524, accel = 0.48768;
  const Vec3 north = Vec3::UnitX(), up = -Vec3::UnitZ();
  const auto free = fastest_chasing(north, limit, accel, 3.0, 0.0, 0.0);
  const auto governed =
      fastest_chasing(north, limit, accel, 3.0, 1.01 * limit, 1.01 * vertical_limit);
  std::printf("horizontal: %.3f m/s free, %.3f governed\n", free.first, governed.first);
  EXPECT_GT(free.first, 1.02 * limit);  // beyond the benchmarks' rule without it
  EXPECT_LT(governed.first, 1.02 * limit);
  // Climbing: the vertical limit likewise.
  const auto free_up = fastest_chasing(up, vertical_limit, accel, 3.0, 0.0, 0.0);
  const auto governed_up =
      fastest_chasing(up, vertical_limit, accel, 3.0, 1.01 * limit, 1.01 * vertical_limit);
  std::printf("vertical: %.3f m/s free, %.3f governed\n", free_up.second, governed_up.second);
  EXPECT_GT(free_up.second, 1.02 * vertical_limit);
  EXPECT_LT(governed_up.second, 1.02 * vertical_limit);
}

/// The largest speed flown at the limit while a constant acceleration the
/// controller does not know of (`unasked`, along the flight) pushes the
/// vehicle: the governor alone holds it back.
double fastest_pushed(double limit, double unasked, double over_limit_gain) {
  ControllerGains gains;
  gains.governor_over_limit = over_limit_gain;
  ClosedLoop loop(limit, 1.524, gains);
  double fastest = 0;
  const double accel = 0.48768;
  const double ramp = limit / accel;
  for (int i = 0; i < static_cast<int>(40.0 / kControlDt); ++i) {
    const double t = i * kControlDt;
    loop.step(speeding_up(Vec3::UnitX(), limit, accel, 0.0, t));
    // The push, after the vehicle is up to speed: its velocity gains what
    // the airframe was not asked for.
    if (t > ramp + 5.0) loop.push(Vec3(unasked * kControlDt, 0, 0));
    fastest = std::max(fastest, loop.state().velocity.norm());
  }
  return fastest;
}

TEST(TrajectoryController, AboveTheLimitTheGovernorBrakesHarder) {
  // Dense seed 130: with 0.1 m/s^2 the vehicle made unasked (its tilt
  // lagging a sweeping heading) it flew 2.2 % over the limit, braked at the
  // velocity gain alone.
  const double limit = 3.048;
  const double plain = fastest_pushed(limit, 0.15, 1.0);
  const double harder = fastest_pushed(limit, 0.15, 3.0);
  EXPECT_GT(plain, 1.02 * limit);
  EXPECT_LT(harder, 1.02 * limit);
  EXPECT_LT(harder - limit, 0.6 * (plain - limit));
}

TEST(TrajectoryController, TheSpeedGovernorLeavesTrackingBelowTheLimitAlone) {
  // A reference that starts on the vehicle and speeds up to 75 % of the
  // limit: the same flight with and without the governor.
  const double limit = 3.048, accel = 0.48768;
  const auto free = fastest_chasing(Vec3::UnitX(), 0.75 * limit, accel, 0.0, 0.0, 0.0);
  const auto governed =
      fastest_chasing(Vec3::UnitX(), 0.75 * limit, accel, 0.0, 1.01 * limit, 1.54);
  EXPECT_LT(free.first, 0.9 * limit);
  EXPECT_NEAR(governed.first, free.first, 1e-9);
}

TEST(TrajectoryController, NaNPositionGivesSafeFiniteControls) {
  TrajectoryController controller{RotorcraftParams{}};
  const RotorcraftParams p;
  VehicleEstimate x;
  x.position = Vec3(kNaNInput, 0, 0);
  const ControlOutput out = controller.step(Reference{}, x, kControlDt);
  EXPECT_FALSE(out.valid);
  EXPECT_TRUE(controls_within_limits(out.controls, p));
  EXPECT_TRUE(out.commanded_accel.allFinite());
}

TEST(TrajectoryController, InfiniteReferenceGivesSafeFiniteControls) {
  TrajectoryController controller{RotorcraftParams{}};
  const RotorcraftParams p;
  Reference ref;
  ref.position = Vec3(kInfInput, 0, 0);
  const ControlOutput out = controller.step(ref, VehicleEstimate{}, kControlDt);
  // Either replaced by the safe hover command, or a finite, limited command.
  EXPECT_TRUE(controls_within_limits(out.controls, p));
  EXPECT_TRUE(out.commanded_accel.allFinite());
  if (!out.valid) {
    EXPECT_EQ(out.controls.as_array(), controller.hover_command().as_array());
  }
}

TEST(TrajectoryController, GarbageInputsNeverGiveNonFiniteOrOutOfLimitControls) {
  const RotorcraftParams p;
  struct Case {
    const char* what;
    Reference ref;
    VehicleEstimate x;
  };
  std::vector<Case> cases;
  auto add = [&](const char* what, auto modify) {
    Case c{what, {}, {}};
    modify(c.ref, c.x);
    cases.push_back(c);
  };
  add("NaN position", [](Reference&, VehicleEstimate& x) { x.position.y() = kNaNInput; });
  add("inf velocity", [](Reference&, VehicleEstimate& x) { x.velocity.x() = kInfInput; });
  add("NaN attitude", [](Reference&, VehicleEstimate& x) {
    x.attitude = Quat(kNaNInput, kNaNInput, kNaNInput, kNaNInput);
  });
  add("NaN body rates", [](Reference&, VehicleEstimate& x) { x.body_rates.z() = kNaNInput; });
  add("inf reference position",
      [](Reference& r, VehicleEstimate&) { r.position.z() = -kInfInput; });
  add("NaN reference velocity", [](Reference& r, VehicleEstimate&) { r.velocity.x() = kNaNInput; });
  add("inf reference acceleration",
      [](Reference& r, VehicleEstimate&) { r.acceleration.y() = kInfInput; });
  add("NaN yaw", [](Reference& r, VehicleEstimate&) { r.yaw = kNaNInput; });
  add("inf yaw rate", [](Reference& r, VehicleEstimate&) { r.yaw_rate = kInfInput; });
  for (const auto& c : cases) {
    TrajectoryController controller{RotorcraftParams{}};
    const ControlOutput out = controller.step(c.ref, c.x, kControlDt);
    EXPECT_TRUE(controls_within_limits(out.controls, p)) << c.what;
    EXPECT_TRUE(out.commanded_accel.allFinite()) << c.what;
    if (!out.valid) {
      // The safe command is the level hover.
      EXPECT_EQ(out.controls.as_array(), controller.hover_command().as_array()) << c.what;
    }
  }
}

TEST(TrajectoryController, RecoversAfterOneGarbageInput) {
  // One corrupt estimate must not poison the controller: good estimates
  // afterwards give valid commands again.
  for (const VehicleEstimate& bad : [] {
         VehicleEstimate nan_position, nan_rates;
         nan_position.position = Vec3(kNaNInput, kNaNInput, kNaNInput);
         nan_rates.body_rates = Vec3(0, 0, kNaNInput);
         return std::vector<VehicleEstimate>{nan_position, nan_rates};
       }()) {
    TrajectoryController controller{RotorcraftParams{}};
    EXPECT_FALSE(controller.step(Reference{}, bad, kControlDt).valid);
    int valid = 0;
    for (int i = 0; i < 100; ++i)
      valid += controller.step(Reference{}, VehicleEstimate{}, kControlDt).valid ? 1 : 0;
    EXPECT_GE(valid, 99) << "good steps after one bad one";
  }
}

TEST(TrajectoryController, HugePositionErrorStaysWithinLimits) {
  const RotorcraftParams p;
  ControllerGains g;
  for (const Vec3& error : {Vec3(1000, 0, 0), Vec3(0, -1000, 0), Vec3(0, 0, 1000),
                            Vec3(0, 0, -1000), Vec3(700, 700, -700)}) {
    ClosedLoop loop;
    Reference ref;
    ref.position = error;
    for (int i = 0; i < 300; ++i) {
      const ControlOutput out = loop.step(ref);
      ASSERT_TRUE(out.valid) << error.transpose() << " step " << i;
      ASSERT_TRUE(controls_within_limits(out.controls, p)) << error.transpose() << " step " << i;
      // The pseudo-control stays within its bounds.
      ASSERT_LE(std::hypot(out.commanded_accel.x(), out.commanded_accel.y()),
                g.max_horizontal_accel + 1e-9);
      ASSERT_LE(std::abs(out.commanded_accel.z()), g.max_vertical_accel + 1e-9);
      EXPECT_TRUE(out.saturated);
    }
    // And the vehicle stays upright while it chases the far reference.
    const Vec3 e = euler_from_quat(loop.state().attitude);
    EXPECT_LT(std::abs(e.x()), deg2rad(40)) << error.transpose();
    EXPECT_LT(std::abs(e.y()), deg2rad(40)) << error.transpose();
  }
}

/// An adaptive element that has learnt a fixed outer-loop share: the model
/// error of an updraft the nominal rotor does not know.
class FixedOuterShare final : public AdaptiveElement {
 public:
  explicit FixedOuterShare(const Vec3& share) : share_(share) {}
  Vec3 outer_output(const AdaptiveInputs&) override { return share_; }
  Vec3 inner_output(const AdaptiveInputs&) override { return Vec3::Zero(); }
  void update(const AdaptiveInputs&) override {}
  void reset() override {}

 private:
  Vec3 share_;
};

TEST(TrajectoryController, TheAdaptiveShareIsNotCutByThePseudoControlBound) {
  // A reference far below: the vertical pseudo-control is at its bound. An
  // updraft the nominal model does not know (the adaptive element has
  // learnt it as -2 m/s^2, i.e. the rotor lifts more than modelled) must
  // still lower the thrust: bounded together, the bound took the share
  // and the vehicle climbed away at full down command.
  const RotorcraftParams p;
  const ControllerGains g;
  Reference ref;
  ref.position = Vec3(0, 0, 200);  // 200 m below (NED)
  auto first_step = [&](const Vec3& share) {
    TrajectoryController controller(p, g, std::make_unique<FixedOuterShare>(share));
    return controller.step(ref, VehicleEstimate{}, kControlDt);
  };
  const ControlOutput plain = first_step(Vec3::Zero());
  const ControlOutput updraft = first_step(Vec3(0, 0, -2.0));
  ASSERT_TRUE(plain.valid && updraft.valid);
  // What is asked of the vehicle is the same, and within the bound.
  EXPECT_NEAR(plain.commanded_accel.z(), g.max_vertical_accel, 1e-9);
  EXPECT_NEAR(updraft.commanded_accel.z(), g.max_vertical_accel, 1e-9);
  EXPECT_TRUE(plain.saturated && updraft.saturated);
  // The thrust is the nominal rotor's for 3 + 2 m/s^2 down: m (g - 5).
  EXPECT_NEAR(plain.thrust, p.mass * (kGravity - g.max_vertical_accel), 0.02 * p.mass * kGravity);
  EXPECT_NEAR(updraft.thrust, p.mass * (kGravity - g.max_vertical_accel - 2.0),
              0.02 * p.mass * kGravity);
}

TEST(TrajectoryController, HoverCommandIsLevelTrim) {
  const TrajectoryController controller{RotorcraftParams{}};
  const RotorcraftModel model;
  const auto t = vehicle::trim(model, Vec3::Zero(), 0.0);
  EXPECT_DOUBLE_EQ(controller.hover_command().collective, t.controls.collective);
  EXPECT_DOUBLE_EQ(controller.hover_command().pedal, t.controls.pedal);
  EXPECT_EQ(controller.hover_command().lon_cyclic, 0.0);
  EXPECT_EQ(controller.hover_command().lat_cyclic, 0.0);
}

}  // namespace
}  // namespace ofn::control
