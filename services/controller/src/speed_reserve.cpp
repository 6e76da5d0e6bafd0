#include "ofn/controller/speed_reserve.hpp"

#include <algorithm>
#include <cmath>

namespace ofn::control {

void SpeedReserve::update(const Vec3& velocity_error, double dt) {
  if (!velocity_error.allFinite() || !std::isfinite(dt) || dt <= 0.0) return;
  const double weight = std::min(1.0, dt / std::max(settings_.time_constant, 1e-9));
  mean_square_ += (velocity_error.squaredNorm() - mean_square_) * weight;
}

// The running mean starts from calm and takes about a time constant to
// learn of gusts. Averaged over the time flown instead (so that a flight
// starting in gusts is measured in its first second), the windy course took
// the whole reserve at once, cruised at 6.5 ft/s, and a headwind gust
// slowed it to 2.2 ft/s from which it raced off at 10.9 ft/s (TUNING.md).
double SpeedReserve::rms() const {
  return std::sqrt(std::max(0.0, mean_square_));
}

double SpeedReserve::reserve(double max_speed) const {
  if (!settings_.enabled || !(max_speed > 0.0)) return 0.0;
  const double sigma = rms();
  if (sigma <= settings_.onset) return 0.0;
  const double span = std::max(settings_.full - settings_.onset, 1e-9);
  const double u = std::clamp((sigma - settings_.onset) / span, 0.0, 1.0);
  const double ramp = u * u * (3.0 - 2.0 * u);  // smoothstep: no step at either end
  return std::min(settings_.sigmas * sigma * ramp, settings_.max_fraction * max_speed);
}

}  // namespace ofn::control
