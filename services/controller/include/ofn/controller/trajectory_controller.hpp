#pragma once
// Trajectory follower by approximate model inversion (after Johnson and
// Kannan's adaptive trajectory controller, paper Fig. 2):
//   outer loop: a reference model driven by the commanded trajectory;
//               errors to it -> acceleration pseudo-control (reference-model
//               acceleration + PID - adaptive share) -> inverted to a thrust
//               vector, i.e. collective and a desired attitude;
//   inner loop: a reference model driven by that attitude; errors to it ->
//               angular-acceleration pseudo-control -> inverted through the
//               nominal rotor model to cyclic and pedal.
// Pseudo-control hedging: what the model says the vehicle cannot do (bounds,
// actuator limits and rates, for the inner loop the disk tilt the flapping
// lag has not yet reached, and for the outer loop the attitude not yet
// reached) is taken out of each reference model's acceleration, so neither
// the adaptive element nor the integrators learn from it.
// The adaptive element plugs in through AdaptiveElement (NeuralAdaptation
// in neural_adaptation.hpp); the default one adds nothing. Pure core: no
// LCM, no clock (dt is passed in).

#include <memory>

#include "ofn/common/frames.hpp"
#include "ofn/rotorcraft_model/rotorcraft_model.hpp"

namespace ofn::control {

struct Reference {
  Vec3 position = Vec3::Zero();
  Vec3 velocity = Vec3::Zero();
  Vec3 acceleration = Vec3::Zero();
  double yaw = 0;       // rad
  double yaw_rate = 0;  // rad/s
};

struct VehicleEstimate {
  Vec3 position = Vec3::Zero();
  Vec3 velocity = Vec3::Zero();
  Quat attitude = Quat::Identity();
  Vec3 body_rates = Vec3::Zero();
};

/// The navigation solution `age` seconds after its time of validity, by
/// the kinematics it carries: position and velocity under the measured
/// acceleration (world), attitude turned by the body rates. The control law
/// acts now; fed the state of 50-100 ms ago (a navigation latency, a slow
/// link) it commands for a vehicle that has moved on, which a loop tuned
/// for a fresh state does not tolerate. `age` is clamped to [0, max_age].
VehicleEstimate predict_estimate(const VehicleEstimate& x, const Vec3& acceleration, double age,
                                 double max_age);

struct ControllerGains {
  // Outer loop per world axis (north, east, down).
  Vec3 position = Vec3(0.64, 0.64, 1.0);  // 1/s^2
  Vec3 velocity = Vec3(1.44, 1.44, 1.8);  // 1/s
  Vec3 integral = Vec3(0.04, 0.04, 0.1);  // 1/s^3
  double integral_limit = 1.0;            // m/s^2, largest integral share
  double integral_band = 1.0;             // m, integrate only errors smaller than this
  // Authority for gusts and a 15 kt crosswind on a heavier airframe.
  double max_horizontal_accel = 5.0;  // m/s^2, pseudo-control bound
  double max_vertical_accel = 3.0;    // m/s^2
  double max_tilt = deg2rad(35.0);    // rad
  // Above a speed limit the governor brakes at this many times the velocity
  // gain. What it must overcome there is acceleration the vehicle makes
  // unasked (the tilt lagging a sweeping heading); at the plain gain an
  // unasked 0.1 m/s^2 holds the vehicle 0.07 m/s (2.2 % of 10 ft/s) over.
  double governor_over_limit = 3.0;
  // Inner loop per body axis (roll, pitch, yaw).
  Vec3 attitude = Vec3(9.0, 9.0, 4.0);           // 1/s^2
  Vec3 rate = Vec3(4.8, 4.8, 4.0);               // 1/s
  Vec3 attitude_integral = Vec3(2.0, 2.0, 1.0);  // 1/s^3
  double attitude_integral_limit = 2.0;          // rad/s^2
  // Reference models: second order, natural frequency and damping per loop.
  double outer_reference_frequency = 1.0;  // rad/s
  double outer_reference_damping = 1.0;
  double inner_reference_frequency = 8.0;  // rad/s
  double inner_reference_damping = 1.0;
  // Pseudo-control hedging: off only to show what it prevents.
  bool hedging = true;
};

/// Inputs an adaptive element sees each step.
struct AdaptiveInputs {
  Vec3 position_error, velocity_error;  // reference model - actual, world
  Vec3 attitude_error, rate_error;      // reference model - actual, body
  Vec3 pseudo_accel, pseudo_angular;    // pseudo-controls before the adaptive share
  Vec3 velocity, body_rates;
  Vec3 body_velocity;  // velocity in body axes
  Vec3 gravity_body;   // unit down vector in body axes (the attitude)
  Vec3 nose_world;     // body x axis in world axes (the heading: a steady wind
                       // loads the airframe differently on every heading)
  // e^T P B of each loop's linear error dynamics (P from the loop gains), and
  // the error norms, for the update law.
  Vec3 outer_error_signal, inner_error_signal;
  double outer_error_norm = 0, inner_error_norm = 0;
  double dt = 0;
};

/// The slot for an online adaptive element (e.g. a neural network with a
/// bounded update law). It returns the share subtracted from each loop's
/// pseudo-control and learns from the tracking errors.
class AdaptiveElement {
 public:
  virtual ~AdaptiveElement() = default;
  virtual Vec3 outer_output(const AdaptiveInputs& in) = 0;
  virtual Vec3 inner_output(const AdaptiveInputs& in) = 0;
  virtual void update(const AdaptiveInputs& in) = 0;
  virtual void reset() = 0;
  /// Size of the adapted weights (0 when nothing adapts), to watch for drift.
  virtual double weight_norm() const { return 0.0; }
};

/// Adds nothing: the non-adaptive baseline.
class NoAdaptation final : public AdaptiveElement {
 public:
  Vec3 outer_output(const AdaptiveInputs&) override { return Vec3::Zero(); }
  Vec3 inner_output(const AdaptiveInputs&) override { return Vec3::Zero(); }
  void update(const AdaptiveInputs&) override {}
  void reset() override {}
};

struct ControlOutput {
  vehicle::Controls controls;
  Vec3 commanded_accel = Vec3::Zero();     // outer pseudo-control, governed, bounded, NED
  Vec3 adaptive_accel = Vec3::Zero();      // adaptive share, taken off it after the bound
  Vec3 adaptive_angular = Vec3::Zero();    // inner-loop adaptive share, rad/s^2
  Vec3 hedge_accel = Vec3::Zero();         // outer hedge: commanded - achievable, m/s^2
  Vec3 hedge_angular = Vec3::Zero();       // inner hedge, rad/s^2
  Vec3 reference_position = Vec3::Zero();  // outer reference model, world NED
  Quat attitude_command = Quat::Identity();
  double thrust = 0;       // N
  bool saturated = false;  // an actuator or pseudo-control bound was hit
  bool valid = true;       // false: non-finite result replaced by a safe command
};

class TrajectoryController {
 public:
  /// `nominal` is the controller's own (approximate) model of the airframe.
  explicit TrajectoryController(vehicle::RotorcraftParams nominal, ControllerGains gains = {},
                                std::unique_ptr<AdaptiveElement> adaptive = nullptr);

  ControlOutput step(const Reference& ref, const VehicleEstimate& x, double dt);
  /// Forgets integrators and adaptation (mode changes, restarts).
  void reset();
  /// The speed governor: the outer loop never asks for more acceleration
  /// along the velocity than the velocity gain times what is left to
  /// `max_speed` (m/s, the 3-D speed) and likewise for `max_vertical_speed`
  /// (m/s, up or down), so that neither the reference model catching up with
  /// a plan it lags nor the feedback on a position error drives the vehicle
  /// beyond the limits, whatever the plan. Near and below them it acts as a
  /// velocity loop saturated at the limit (braking harder above it, by
  /// `governor_over_limit`); far below it does nothing.
  /// Zero turns a limit off (the default).
  void set_speed_limits(double max_speed, double max_vertical_speed);
  /// Level-attitude hover command, the safe output when inputs are bad.
  vehicle::Controls hover_command() const { return hover_; }
  const ControllerGains& gains() const { return gains_; }
  const vehicle::RotorcraftModel& nominal_model() const { return model_; }
  const AdaptiveElement& adaptive() const { return *adaptive_; }

 private:
  // step() in stages, as the loops are drawn: each reads and writes the
  // step's signals and fills its part of the output.
  struct StepSignals;
  /// Outer loop: reference model, PID and adaptive share -> the governed,
  /// bounded acceleration command (out->commanded_accel).
  void outer_loop(const Reference& ref, const VehicleEstimate& x, StepSignals& s,
                  ControlOutput* out);
  /// The thrust vector for that acceleration -> thrust, attitude command
  /// and collective.
  void invert_for_thrust(double yaw, StepSignals& s, ControlOutput* out) const;
  /// Inner loop: reference model, PID and adaptive share -> angular
  /// acceleration, inverted through the nominal rotor to cyclic and pedal.
  void inner_loop(double yaw_rate, const VehicleEstimate& x, StepSignals& s, ControlOutput* out);
  void clamp_to_actuator_limits(ControlOutput* out) const;
  /// Pseudo-control hedging: commanded less what the nominal model says
  /// these controls achieve (servo rates, flapping lag, the reference
  /// attitude rather than the commanded one).
  void hedge(const Vec3& body_rates, const StepSignals& s, ControlOutput* out);
  void advance_reference_models(const StepSignals& s, ControlOutput* out);
  double collective_for_thrust(double thrust, const Vec3& air_body) const;
  /// `accel` with the speed governor applied at `velocity`.
  Vec3 govern_speed(const Vec3& accel, const Vec3& velocity) const;
  /// Angular acceleration the nominal model gives for the pedal and a disk
  /// tilted by `flap_lon` / `flap_lat` (rad): the inverse of the inner
  /// loop's inversion.
  Vec3 angular_accel_for(const vehicle::Controls& c, double thrust, const Vec3& air_body,
                         const Vec3& body_rates, double rotor_torque, double flap_lon,
                         double flap_lat) const;

  vehicle::RotorcraftModel model_;
  ControllerGains gains_;
  std::unique_ptr<AdaptiveElement> adaptive_;
  vehicle::Controls hover_;
  Vec3 position_integral_ = Vec3::Zero();
  double governed_speed_ = 0;           // m/s, 0: no governor
  double governed_vertical_speed_ = 0;  // m/s, 0: no governor
  Vec3 attitude_integral_ = Vec3::Zero();
  double tail_thrust_estimate_ = 0;  // N, side force of the tail rotor
  double hover_tail_thrust_ = 0;     // N, its hover value, after a reset
  // Reference models; started at the vehicle's state on the first step
  // after a reset.
  bool reference_started_ = false;
  Vec3 ref_position_ = Vec3::Zero(), ref_velocity_ = Vec3::Zero();
  Quat ref_attitude_ = Quat::Identity();
  Vec3 ref_rates_ = Vec3::Zero();
  // Actuator positions the nominal servos can have reached (rate limits).
  vehicle::Controls actuator_estimate_;
  // Disk tilt the nominal rotor has reached (rad, flapping lag).
  bool flap_started_ = false;
  double flap_lon_ = 0, flap_lat_ = 0;
  // Error-dynamics weights e^T P B per axis: position/attitude and rate terms.
  Vec3 outer_p12_, outer_p22_, inner_p12_, inner_p22_;
};

}  // namespace ofn::control
