#include "ofn/rotorcraft_model/rotorcraft_model.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Dense>

namespace ofn::vehicle {

Controls clamp_controls(const Controls& c, const RotorcraftParams& p) {
  auto lim = [](double v, double lo, double hi) { return std::clamp(v, lo, hi); };
  return {lim(c.collective, p.min_controls.collective, p.max_controls.collective),
          lim(c.lon_cyclic, p.min_controls.lon_cyclic, p.max_controls.lon_cyclic),
          lim(c.lat_cyclic, p.min_controls.lat_cyclic, p.max_controls.lat_cyclic),
          lim(c.pedal, p.min_controls.pedal, p.max_controls.pedal)};
}

std::optional<std::string> controls_beyond_limits(const Controls& command,
                                                  const RotorcraftParams& params,
                                                  double tolerance) {
  static const char* const kNames[4] = {"collective", "longitudinal cyclic", "lateral cyclic",
                                        "pedal"};
  const auto c = command.as_array();
  const auto lo = params.min_controls.as_array();
  const auto hi = params.max_controls.as_array();
  for (int i = 0; i < 4; ++i)
    if (!(c[i] >= lo[i] - tolerance && c[i] <= hi[i] + tolerance))
      return std::string(kNames[i]) + " beyond its limits";
  return std::nullopt;
}

RotorcraftModel::RotorcraftModel(RotorcraftParams params) : params_(std::move(params)) {}

double RotorcraftModel::thrust(double collective, double induced_velocity,
                               const Vec3& air_body) const {
  const auto& p = params_;
  const double tip = p.tip_speed();
  const double mu = std::hypot(air_body.x(), air_body.y()) / tip;
  // Net flow down through the disk: induced velocity less the descent rate.
  const double lambda = (induced_velocity - air_body.z()) / tip;
  const double ct =
      0.5 * p.lift_slope * p.solidity * (collective * (1.0 / 3.0 + 0.5 * mu * mu) - 0.5 * lambda);
  return std::max(0.0, ct) * p.air_density * p.disk_area() * tip * tip;
}

double RotorcraftModel::steady_induced_velocity(double collective, const Vec3& air_body) const {
  const auto& p = params_;
  const double horizontal = std::hypot(air_body.x(), air_body.y());
  // Momentum theory: v_i = T / (2 rho A |V_rotor|), solved by bisection since
  // T itself falls as the inflow grows.
  auto excess = [&](double vi) {
    const double t = thrust(collective, vi, air_body);
    const double flow = std::max(0.5, std::hypot(horizontal, vi - air_body.z()));
    return vi - t / (2.0 * p.air_density * p.disk_area() * flow);
  };
  double lo = 0.0, hi = 60.0;
  if (excess(lo) >= 0) return 0.0;
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (lo + hi);
    (excess(mid) > 0 ? hi : lo) = mid;
  }
  return 0.5 * (lo + hi);
}

RotorcraftDerivative RotorcraftModel::derivative(const RotorcraftState& s, const Controls& command,
                                                 const Vec3& wind,
                                                 RotorcraftLoads* loads_out) const {
  const auto& p = params_;
  const Mat3 world_from_body = s.attitude.toRotationMatrix();
  const Vec3 air_body = world_from_body.transpose() * (s.velocity - wind);
  const Vec3& w = s.body_rates;
  const Controls& act = s.actuators;
  RotorcraftDerivative d;
  RotorcraftLoads loads;

  // Main rotor thrust and inflow lag.
  loads.thrust = thrust(act.collective, s.induced_velocity, air_body);
  const double horizontal = std::hypot(air_body.x(), air_body.y());
  const double flow = std::max(0.5, std::hypot(horizontal, s.induced_velocity - air_body.z()));
  const double inflow_target = loads.thrust / (2.0 * p.air_density * p.disk_area() * flow);
  d.inflow_dot = (inflow_target - s.induced_velocity) / p.inflow_time_constant;

  // Tip-path plane: first order toward the cyclic command less blow-back;
  // the disk lags body rotation (it stays put in inertial space).
  const double lon_ss = p.cyclic_to_flap * act.lon_cyclic - p.flap_blowback * air_body.x();
  const double lat_ss = p.cyclic_to_flap * act.lat_cyclic - p.flap_blowback * air_body.y();
  d.flap_lon_dot = w.y() - (s.flap_lon - lon_ss) / p.flap_time_constant;
  d.flap_lat_dot = -w.x() - (s.flap_lat - lat_ss) / p.flap_time_constant;

  const Vec3 rotor_force = loads.thrust * Vec3(std::sin(s.flap_lon), std::sin(s.flap_lat),
                                               -std::cos(s.flap_lon) * std::cos(s.flap_lat));
  // Torque reaction of the main rotor (induced, climb and profile power).
  const double tip = p.tip_speed();
  const double mu = horizontal / tip;
  const double profile_power = p.air_density * p.disk_area() * tip * tip * tip * p.solidity *
                               p.profile_drag / 8.0 * (1.0 + 4.6 * mu * mu);
  loads.rotor_torque =
      (loads.thrust * (s.induced_velocity - air_body.z()) + profile_power) / p.rotor_speed;

  // Tail rotor: positive pedal yaws the nose right, i.e. pushes the tail left.
  const double tail_side_flow = air_body.y() - w.z() * p.tail_arm;
  loads.tail_thrust = -p.tail_thrust_per_rad * act.pedal - p.tail_velocity_damping * tail_side_flow;

  const Vec3 drag =
      -0.5 * p.air_density * p.drag_area.cwiseProduct(air_body.cwiseAbs()).cwiseProduct(air_body);
  loads.force_body = rotor_force + Vec3(0.0, loads.tail_thrust, 0.0) + drag;
  loads.moment_body = Vec3(p.hub_height * rotor_force.y() + p.flap_stiffness * s.flap_lat,
                           -p.hub_height * rotor_force.x() - p.flap_stiffness * s.flap_lon,
                           loads.rotor_torque - p.tail_arm * loads.tail_thrust);

  d.position_dot = s.velocity;
  d.velocity_dot = world_from_body * loads.force_body / p.mass + Vec3(0, 0, kGravity);
  const Vec3 inertia_w = p.inertia.cwiseProduct(w);
  d.rates_dot = (loads.moment_body - w.cross(inertia_w)).cwiseQuotient(p.inertia);
  const Quat omega(0.0, w.x(), w.y(), w.z());
  const Quat qd = s.attitude * omega;
  d.attitude_dot = 0.5 * Eigen::Vector4d(qd.w(), qd.x(), qd.y(), qd.z());

  // Servos: first-order lag toward the (clamped) command, rate limited.
  const auto target = clamp_controls(command, p).as_array();
  const auto now = act.as_array();
  const auto rate = p.actuator_rate.as_array();
  for (int i = 0; i < 4; ++i)
    d.actuator_dot[i] = std::clamp((target[i] - now[i]) / p.servo_time_constant, -rate[i], rate[i]);
  if (loads_out) *loads_out = loads;
  return d;
}

TrimResult trim(const RotorcraftModel& model, const Vec3& velocity, double yaw, const Vec3& wind) {
  const auto& p = model.params();
  // Unknowns: collective, lon cyclic, lat cyclic, pedal, roll, pitch.
  using Vec6 = Eigen::Matrix<double, 6, 1>;
  auto build = [&](const Vec6& x) {
    RotorcraftState s;
    s.velocity = velocity;
    s.attitude = quat_from_euler(x[4], x[5], yaw);
    s.actuators = {x[0], x[1], x[2], x[3]};
    const Vec3 air_body = s.attitude.toRotationMatrix().transpose() * (velocity - wind);
    s.flap_lon = p.cyclic_to_flap * x[1] - p.flap_blowback * air_body.x();
    s.flap_lat = p.cyclic_to_flap * x[2] - p.flap_blowback * air_body.y();
    s.induced_velocity = model.steady_induced_velocity(x[0], air_body);
    return s;
  };
  auto residual = [&](const Vec6& x) {
    const RotorcraftState s = build(x);
    const auto d = model.derivative(s, s.actuators, wind);
    Vec6 r;
    r << d.velocity_dot, d.rates_dot;
    return r;
  };
  Vec6 x;
  x << 0.15, 0, 0, -0.1, 0, 0;
  TrimResult out;
  for (int iter = 0; iter < 60; ++iter) {
    const Vec6 r = residual(x);
    out.residual = r.cwiseAbs().maxCoeff();
    if (out.residual < 1e-9) break;
    Eigen::Matrix<double, 6, 6> jac;
    for (int j = 0; j < 6; ++j) {
      Vec6 xp = x;
      const double h = 1e-6;
      xp[j] += h;
      jac.col(j) = (residual(xp) - r) / h;
    }
    const Vec6 dx = jac.colPivHouseholderQr().solve(-r);
    x += dx.cwiseMax(-0.05).cwiseMin(0.05);  // damped: keep Newton steps small
  }
  out.residual = residual(x).cwiseAbs().maxCoeff();
  out.converged = out.residual < 1e-6;
  out.controls = {x[0], x[1], x[2], x[3]};
  out.state = build(x);
  return out;
}

}  // namespace ofn::vehicle
