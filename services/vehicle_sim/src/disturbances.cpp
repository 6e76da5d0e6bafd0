#include "ofn/vehicle_sim/disturbances.hpp"

#include <algorithm>
#include <cmath>

namespace ofn::vehicle {
namespace {

// Separate streams, so that switching one disturbance on does not reshuffle
// the others.
constexpr uint32_t kNavStreamOffset = 0x9E3779B9u;

}  // namespace

double GaussianStream::next() {
  const double u1 = 1.0 - uniform();  // (0, 1]
  const double u2 = uniform();
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * kPi * u2);
}

DrydenParams dryden_low_altitude(double altitude_m, double wind_at_20ft) {
  const double h = std::clamp(altitude_m / kMetresPerFoot, 10.0, 1000.0);  // ft
  const double base = 0.177 + 0.000823 * h;
  DrydenParams p;
  const double sigma_w = 0.1 * wind_at_20ft;
  const double sigma_uv = sigma_w / std::pow(base, 0.4);
  p.sigma = Vec3(sigma_uv, sigma_uv, sigma_w);
  const double l_uv = h / std::pow(base, 1.2) * kMetresPerFoot;
  p.scale_length = Vec3(l_uv, l_uv, h * kMetresPerFoot);
  return p;
}

Vec3 DrydenTurbulence::step(double dt, double airspeed, const DrydenParams& params) {
  const double v = std::max(airspeed, kMinAirspeed);
  const double sqrt3 = std::sqrt(3.0);
  for (int i = 0; i < 3; ++i) {
    const double lag = params.scale_length[i] / v;  // s
    const double phi = std::exp(-dt / lag);
    // The second stage lags the first; both are exact discretisations of
    // first-order lags, which at physics steps far shorter than L/V keep
    // the continuous variances (1 and 1/2, covariance 1/2).
    second_[i] = phi * second_[i] + (1.0 - phi) * first_[i];
    first_[i] = phi * first_[i] + std::sqrt(1.0 - phi * phi) * noise_.next();
  }
  gust_.x() = params.sigma.x() * first_.x();
  // (1 + sqrt(3) T s) / (1 + T s)^2 applied to white noise is
  // sqrt(3) x1 + (1 - sqrt(3)) x2 with x1 the first lag and x2 the second;
  // its variance is 2 for unit-variance x1.
  for (int i = 1; i < 3; ++i)
    gust_[i] = params.sigma[i] / std::sqrt(2.0) * (sqrt3 * first_[i] + (1.0 - sqrt3) * second_[i]);
  return gust_;
}

RotorcraftParams apply_variation(RotorcraftParams p, const VehicleVariation& v) {
  p.mass *= v.mass_scale;
  p.inertia = p.inertia.cwiseProduct(v.inertia_scale);
  p.servo_time_constant *= v.actuator_time_scale;
  p.flap_time_constant *= v.actuator_time_scale;
  if (v.collective_min) p.min_controls.collective = *v.collective_min;
  if (v.collective_max) p.max_controls.collective = *v.collective_max;
  if (v.cyclic_limit) {
    p.min_controls.lon_cyclic = p.min_controls.lat_cyclic = -*v.cyclic_limit;
    p.max_controls.lon_cyclic = p.max_controls.lat_cyclic = *v.cyclic_limit;
  }
  if (v.pedal_limit) {
    p.min_controls.pedal = -*v.pedal_limit;
    p.max_controls.pedal = *v.pedal_limit;
  }
  if (v.collective_rate) p.actuator_rate.collective = *v.collective_rate;
  if (v.cyclic_rate) p.actuator_rate.lon_cyclic = p.actuator_rate.lat_cyclic = *v.cyclic_rate;
  if (v.pedal_rate) p.actuator_rate.pedal = *v.pedal_rate;
  return p;
}

SimulatedVehicle::SimulatedVehicle(const RotorcraftParams& airframe, const Vec3& steady_wind,
                                   const Disturbances& disturbances, double ground_altitude)
    : model_(airframe),
      steady_wind_(steady_wind),
      disturbances_(disturbances),
      ground_altitude_(ground_altitude),
      turbulence_(disturbances.seed),
      nav_noise_(disturbances.seed + kNavStreamOffset) {
  model_.set_wind(steady_wind_);
}

void SimulatedVehicle::reset(const RotorcraftState& state, double t) {
  model_.set_state(state);
  time_ = t;
  history_.clear();
  record();
}

void SimulatedVehicle::hold(const RotorcraftState& state, double dt) {
  model_.set_state(state);
  time_ += dt;
  record();
}

void SimulatedVehicle::step(double dt) {
  const TurbulenceSpec& spec = disturbances_.turbulence;
  if (spec.active()) {
    const RotorcraftState& s = model_.state();
    const double altitude = -s.position.z() - ground_altitude_;
    dryden_ = dryden_low_altitude(altitude, spec.wind_at_20ft);
    if (spec.sigma) dryden_.sigma = *spec.sigma;
    if (spec.scale_length) dryden_.scale_length = *spec.scale_length;
    const Vec3 air = s.velocity - steady_wind_;
    // Path axes: u along the horizontal air velocity (the heading when
    // there is hardly any), v to its right, w down.
    const double horizontal = std::hypot(air.x(), air.y());
    const double track =
        horizontal > 0.5 ? std::atan2(air.y(), air.x()) : euler_from_quat(s.attitude).z();
    const Vec3 g = turbulence_.step(dt, air.norm(), dryden_);
    const double c = std::cos(track), sn = std::sin(track);
    gust_ned_ = Vec3(c * g.x() - sn * g.y(), sn * g.x() + c * g.y(), g.z());
    model_.set_wind(steady_wind_ + gust_ned_);
  }
  model_.step(dt);
  time_ += dt;
  record();
}

void SimulatedVehicle::record() {
  const RotorcraftState& s = model_.state();
  NavSample n;
  n.time = time_;
  n.position = s.position;
  n.velocity = s.velocity;
  n.attitude = s.attitude;
  n.body_rates = s.body_rates;
  n.acceleration = model_.acceleration();
  history_.push_back(n);
  // Keep just enough history to reach back by the latency: the front is the
  // newest sample at least that old.
  const double oldest_needed = time_ - disturbances_.nav.latency + 1e-9;
  while (history_.size() > 1 && history_[1].time <= oldest_needed) history_.pop_front();
}

NavSample SimulatedVehicle::measure() {
  const NavErrorSpec& e = disturbances_.nav;
  NavSample n = history_.front();  // the state `latency` ago (see record())
  // Always the same draws, so that one noise level does not reshuffle the rest.
  const Vec3 dp = nav_noise_.next3(), dv = nav_noise_.next3(), da = nav_noise_.next3(),
             dw = nav_noise_.next3();
  n.position += e.position_sigma * dp;
  n.velocity += e.velocity_sigma * dv;
  const Vec3 tilt = e.attitude_sigma * da;
  if (tilt.norm() > 0)
    n.attitude =
        (n.attitude * Quat(Eigen::AngleAxisd(tilt.norm(), tilt.normalized()))).normalized();
  n.body_rates += e.rate_sigma * dw;
  return n;
}

}  // namespace ofn::vehicle
