#include "ofn/vehicle_sim/rotorcraft_simulation.hpp"

#include <utility>

namespace ofn::vehicle {
namespace {

/// s + h * d, the Runge-Kutta stage state.
RotorcraftState advance(const RotorcraftState& s, const RotorcraftDerivative& d, double h) {
  RotorcraftState out = s;
  out.position += h * d.position_dot;
  out.velocity += h * d.velocity_dot;
  out.body_rates += h * d.rates_dot;
  Eigen::Vector4d q(s.attitude.w(), s.attitude.x(), s.attitude.y(), s.attitude.z());
  q += h * d.attitude_dot;
  out.attitude = Quat(q[0], q[1], q[2], q[3]).normalized();
  out.flap_lon += h * d.flap_lon_dot;
  out.flap_lat += h * d.flap_lat_dot;
  out.induced_velocity += h * d.inflow_dot;
  auto a = s.actuators.as_array();
  for (int i = 0; i < 4; ++i) a[i] += h * d.actuator_dot[i];
  out.actuators = Controls::from_array(a);
  return out;
}

}  // namespace

RotorcraftSimulation::RotorcraftSimulation(RotorcraftParams params)
    : RotorcraftModel(std::move(params)) {}

void RotorcraftSimulation::set_command(const Controls& command) {
  command_ = clamp_controls(command, params());
}

void RotorcraftSimulation::step(double dt) {
  const RotorcraftState& s = state_;
  const auto k1 = derivative(s, command_, wind_, &loads_);
  const auto k2 = derivative(advance(s, k1, 0.5 * dt), command_, wind_);
  const auto k3 = derivative(advance(s, k2, 0.5 * dt), command_, wind_);
  const auto k4 = derivative(advance(s, k3, dt), command_, wind_);
  RotorcraftDerivative sum = k1;
  auto combine = [](auto a, auto b, auto c, auto d) { return (a + 2.0 * b + 2.0 * c + d) / 6.0; };
  sum.position_dot = combine(k1.position_dot, k2.position_dot, k3.position_dot, k4.position_dot);
  sum.velocity_dot = combine(k1.velocity_dot, k2.velocity_dot, k3.velocity_dot, k4.velocity_dot);
  sum.rates_dot = combine(k1.rates_dot, k2.rates_dot, k3.rates_dot, k4.rates_dot);
  sum.attitude_dot = combine(k1.attitude_dot, k2.attitude_dot, k3.attitude_dot, k4.attitude_dot);
  sum.flap_lon_dot = combine(k1.flap_lon_dot, k2.flap_lon_dot, k3.flap_lon_dot, k4.flap_lon_dot);
  sum.flap_lat_dot = combine(k1.flap_lat_dot, k2.flap_lat_dot, k3.flap_lat_dot, k4.flap_lat_dot);
  sum.inflow_dot = combine(k1.inflow_dot, k2.inflow_dot, k3.inflow_dot, k4.inflow_dot);
  for (int i = 0; i < 4; ++i)
    sum.actuator_dot[i] =
        combine(k1.actuator_dot[i], k2.actuator_dot[i], k3.actuator_dot[i], k4.actuator_dot[i]);
  state_ = advance(s, sum, dt);
  acceleration_ = sum.velocity_dot;
}

}  // namespace ofn::vehicle
