#pragma once
// 6-DOF rigid-body model of a Yamaha RMAX-class helicopter: its parameters,
// state and equations of motion. Pure core: no LCM, no clock, and no state
// of its own: derivative() gives the rate of change of a state under a
// command and a wind. The simulator integrates it as the truth
// (RotorcraftSimulation, vehicle_sim); the controller inverts it as its
// nominal model of the airframe, with its own parameters.
//
// Components: main-rotor thrust from collective by blade-element theory with
// a momentum-theory inflow that lags (first order); first-order
// tip-path-plane flapping driven by cyclic with rate feedback (gyroscopic
// lag) and speed blow-back; hub moment from thrust tilt and flapping
// stiffness; tail rotor thrust for yaw with its side force; main-rotor
// torque; quadratic fuselage drag against the air mass (steady wind);
// gravity; actuator position limits, rate limits and servo lag.

#include <array>
#include <optional>
#include <string>

#include "ofn/common/frames.hpp"

namespace ofn::vehicle {

/// Rotor control inputs, radians (blade pitch / swashplate tilt).
struct Controls {
  double collective = 0;  // main-rotor collective pitch
  double lon_cyclic = 0;  // positive tilts the disk forward (nose down)
  double lat_cyclic = 0;  // positive tilts the disk right (roll right)
  double pedal = 0;       // positive yaws the nose right

  std::array<double, 4> as_array() const { return {collective, lon_cyclic, lat_cyclic, pedal}; }
  static Controls from_array(const std::array<double, 4>& a) { return {a[0], a[1], a[2], a[3]}; }
};

/// Physical parameters. Defaults describe an RMAX-class airframe: rotor size,
/// speed and mass from the manufacturer's published data (rotor diameter
/// 3.115 m, tail rotor 0.545 m, length 3.63 m, max take-off mass 94 kg,
/// rotor speed about 850 rpm); inertias, aerodynamic coefficients and time
/// constants are engineering estimates of the same order as published
/// small-helicopter identification results (Mettler et al.), not an
/// identified model of any airframe. docs/VEHICLE_MODEL.md lists them.
struct RotorcraftParams {
  double mass = 80.0;                    // kg (airframe + avionics + fuel)
  Vec3 inertia = Vec3(8.0, 22.0, 18.0);  // kg m^2, body principal axes
  double air_density = 1.225;            // kg/m^3

  // Main rotor
  double rotor_radius = 1.5575;        // m
  double rotor_speed = 89.0;           // rad/s (850 rpm)
  double lift_slope = 5.7;             // per rad
  double solidity = 0.053;             // 2 blades, 0.13 m chord
  double profile_drag = 0.010;         // blade section drag coefficient
  double inflow_time_constant = 0.10;  // s, lag of induced velocity
  double hub_height = 0.60;            // m, hub above the centre of mass
  double flap_stiffness = 200.0;       // N m/rad, effective hub spring
  double flap_time_constant = 0.15;    // s, rotor + stabiliser bar
  double cyclic_to_flap = 1.0;         // rad of disk tilt per rad of cyclic
  double flap_blowback = 0.010;        // rad of disk tilt per m/s of airspeed

  // Tail rotor (pushes the tail to the right for positive thrust)
  double tail_arm = 1.90;              // m behind the centre of mass
  double tail_thrust_per_rad = 355.0;  // N per rad of tail pitch
  double tail_velocity_damping = 5.0;  // N per m/s of sideways flow at the tail

  // Fuselage drag areas (body axes), m^2
  Vec3 drag_area = Vec3(0.30, 1.10, 1.30);

  // Actuators: limits, rates and servo lag
  Controls min_controls{-0.05, -0.16, -0.16, -0.40};
  Controls max_controls{0.30, 0.16, 0.16, 0.40};
  Controls actuator_rate{1.5, 1.5, 1.5, 1.5};  // rad/s, per channel
  double servo_time_constant = 0.04;           // s

  double disk_area() const { return kPi * rotor_radius * rotor_radius; }
  double tip_speed() const { return rotor_speed * rotor_radius; }
};

/// Full state. Attitude is the body-to-world quaternion.
struct RotorcraftState {
  Vec3 position = Vec3::Zero();  // m, NED
  Vec3 velocity = Vec3::Zero();  // m/s, NED
  Quat attitude = Quat::Identity();
  Vec3 body_rates = Vec3::Zero();  // rad/s
  double flap_lon = 0;             // rad, disk tilt forward relative to the shaft
  double flap_lat = 0;             // rad, disk tilt right
  double induced_velocity = 0;     // m/s, main-rotor inflow
  Controls actuators;              // actual actuator positions
};

/// Forces and moments of one evaluation, for inspection and tests.
struct RotorcraftLoads {
  double thrust = 0;        // N
  double rotor_torque = 0;  // N m
  double tail_thrust = 0;   // N
  Vec3 force_body = Vec3::Zero();
  Vec3 moment_body = Vec3::Zero();
};

/// Time derivative of the state (quaternion derivative as a 4-vector w x y z).
struct RotorcraftDerivative {
  Vec3 position_dot, velocity_dot, rates_dot;
  Eigen::Vector4d attitude_dot;
  double flap_lon_dot = 0, flap_lat_dot = 0, inflow_dot = 0;
  std::array<double, 4> actuator_dot{};
};

/// The command within the actuators' position limits.
Controls clamp_controls(const Controls& command, const RotorcraftParams& params);

/// Which actuator a command drives beyond its position limits (by more than
/// `tolerance`, rad), or nullopt: the simulator refuses such a command
/// rather than quietly clamp what no healthy controller sends.
std::optional<std::string> controls_beyond_limits(const Controls& command,
                                                  const RotorcraftParams& params,
                                                  double tolerance = 1e-6);

/// The equations of motion for one set of parameters.
class RotorcraftModel {
 public:
  explicit RotorcraftModel(RotorcraftParams params = {});

  const RotorcraftParams& params() const { return params_; }

  /// Derivative of a state under a command (clamped to the position limits
  /// before the servos follow it) and the air mass's velocity `wind` (NED);
  /// also returns the loads.
  RotorcraftDerivative derivative(const RotorcraftState& s, const Controls& command,
                                  const Vec3& wind, RotorcraftLoads* loads = nullptr) const;

  /// Main-rotor thrust and the matching steady induced velocity for a
  /// collective and the air velocity in body axes (used by trim and by the
  /// controller's approximate inversion).
  double thrust(double collective, double induced_velocity, const Vec3& air_body) const;
  double steady_induced_velocity(double collective, const Vec3& air_body) const;

 private:
  RotorcraftParams params_;
};

/// Result of a trim search.
struct TrimResult {
  bool converged = false;
  RotorcraftState state;  // with flapping, inflow and actuators at equilibrium
  Controls controls;
  double residual = 0;  // largest |acceleration| component left, SI
};

/// Finds controls and roll/pitch for steady flight at `velocity` (NED) with
/// heading `yaw` and zero body rates, in `wind`. Newton iteration.
TrimResult trim(const RotorcraftModel& model, const Vec3& velocity, double yaw,
                const Vec3& wind = Vec3::Zero());

}  // namespace ofn::vehicle
