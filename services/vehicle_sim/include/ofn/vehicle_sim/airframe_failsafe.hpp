#pragma once
// The simulated airframe's own low-level failsafe: what a real rotorcraft
// has below its flight computer (the Yamaha RMAX's attitude control
// system, a servo board's signal-loss failsafe, PX4's hold when setpoints
// stop). When the flight computer's actuator commands stop, the airframe's
// stabiliser takes over: it levels the attitude and damps the velocity
// towards a hover, and hands back as soon as commands arrive again.
//
// This is part of the simulated airframe, not flight code: the controller
// never links it. It flies on the truth state (the airframe's own gyros
// and velocity sensing, taken as exact). Pure core: no LCM, no clock; times
// are seconds of simulated time given by the caller.
//
// The law (SI, body angles in rad, NED, the hover trim of the airframe in
// still air as its centre; psi the heading, u and v the horizontal speed
// forward and to the right in heading axes, w the vertical speed down):
//
//   a_fwd = -k_v u,  a_right = -k_v v          (|a| <= g tan(max_tilt))
//   theta* = theta_h + atan(-a_fwd / g),  phi* = phi_h + atan(a_right / g)
//   lon_cyclic = lon_h - K_att (theta* - theta) + K_rate q
//   lat_cyclic = lat_h + K_att (phi* - phi)     - K_rate p
//   pedal      = pedal_h + K_psi (psi_0 - psi)  - K_r r
//   collective = coll_h + K_w w + K_z (z - z_0)
//
// with psi_0 and z_0 the heading and height at the takeover; every output
// within the airframe's actuator position limits. Proportional only: a
// steady wind leaves a slow drift (the stabiliser holds no position).

#include <optional>

#include "ofn/common/frames.hpp"
#include "ofn/rotorcraft_model/rotorcraft_model.hpp"

namespace ofn::vehicle {

/// Gains of the stabiliser's law (see the file comment). The defaults
/// bring an RMAX-class airframe from a trimmed 10 ft/s to below 0.1 m/s
/// and within 1 deg of the hover attitude in about 4 s, without ever
/// speeding it up (the rotor's blow-back pitches it up by up to 10 deg
/// on the way).
struct StabiliserGains {
  double velocity_damping = 0.3;   // k_v, 1/s: acceleration asked per m/s of speed
  double max_tilt = deg2rad(8.0);  // rad, the damping's tilt from hover trim at most
  double attitude_gain = 0.3;      // K_att, rad of cyclic per rad of roll or pitch error
  double rate_gain = 0.02;         // K_rate, rad of cyclic per rad/s of roll or pitch rate
  double heading_gain = 0.1;       // K_psi, rad of pedal per rad of heading error
  double yaw_rate_gain = 0.06;     // K_r, rad of pedal per rad/s of yaw rate
  double climb_damping = 0.03;     // K_w, rad of collective per m/s of descent
  double height_gain = 0.005;      // K_z, rad of collective per m below the takeover height
};

/// The attitude-hold and velocity-damping law of the airframe.
class HoverStabiliser {
 public:
  /// Trims `airframe` for a hover in still air; throws std::invalid_argument
  /// when it has none (an airframe that cannot hover).
  explicit HoverStabiliser(const RotorcraftParams& airframe, StabiliserGains gains = {});

  /// Holds the heading and height of `s` from now on.
  void engage(const RotorcraftState& s);
  /// The controls for state `s`, within the actuator position limits.
  Controls command(const RotorcraftState& s) const;

  const Controls& hover_trim() const { return hover_; }
  const StabiliserGains& gains() const { return gains_; }

 private:
  RotorcraftParams airframe_;
  StabiliserGains gains_;
  Controls hover_;
  double hover_roll_ = 0;
  double hover_pitch_ = 0;
  double hold_heading_ = 0;
  double hold_down_ = 0;  // m, NED z held
};

/// The actuator-command watchdog and the stabiliser it hands the airframe
/// to. Armed by the first valid command (a vehicle no flight computer has
/// commanded yet flies as it was set up); from then on, when no valid
/// command has arrived for `command_timeout` s, the stabiliser flies until
/// the next one.
class AirframeFailsafe {
 public:
  /// `command_timeout` s (> 0), or 0: never takes over. Throws
  /// std::invalid_argument for a negative or non-finite timeout, or as
  /// HoverStabiliser does.
  AirframeFailsafe(const RotorcraftParams& airframe, double command_timeout,
                   StabiliserGains gains = {});

  /// A valid command arrived at time t (s). Returns true when it ends a
  /// takeover: the command flies again from now.
  bool command_received(double t);
  /// Before each physics step at time t (s) with the truth state: the
  /// stabiliser's controls while it flies the airframe, nullopt while the
  /// flight computer's last command stands. Takes over here once the
  /// last command is more than command_timeout old.
  std::optional<Controls> update(double t, const RotorcraftState& s);

  bool enabled() const { return timeout_ > 0; }
  bool armed() const { return last_command_.has_value(); }
  bool engaged() const { return engaged_; }
  /// Takeovers so far, and the time the last one began (s).
  int takeovers() const { return takeovers_; }
  double engaged_since() const { return engaged_since_; }
  /// Time of the last valid command (s), if any.
  const std::optional<double>& last_command() const { return last_command_; }
  double command_timeout() const { return timeout_; }
  const HoverStabiliser& stabiliser() const { return stabiliser_; }

 private:
  HoverStabiliser stabiliser_;
  double timeout_;
  std::optional<double> last_command_;
  bool engaged_ = false;
  int takeovers_ = 0;
  double engaged_since_ = 0;
};

}  // namespace ofn::vehicle
