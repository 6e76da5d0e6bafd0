#pragma once
// The stop every plan carries: from a reference state, decelerate along the
// velocity at a constant rate to a hover, then hold there. The RH optimiser
// checks this stop before it commits a plan, and the controller flies the
// same stop when the plans stop coming, so what was checked is what is
// flown. Pure, header-only, SI units, world NED.

#include <algorithm>
#include <cmath>

#include "ofn/common/frames.hpp"

namespace ofn {

/// Below this speed (m/s) a state counts as a hover: no braking piece.
constexpr double kHoverSpeed = 1e-3;

struct StopProfile {
  Vec3 start = Vec3::Zero();     // m, world NED
  Vec3 velocity = Vec3::Zero();  // m/s at the start
  double deceleration = 1.0;     // m/s^2, > 0
  double stop_time = 0;          // s to the hover

  Vec3 stop_point() const { return start + 0.5 * velocity * stop_time; }
  double distance() const { return 0.5 * velocity.norm() * stop_time; }
  /// State `t` seconds after the start (held at the hover afterwards).
  Vec3 position(double t) const {
    const double s = std::clamp(t, 0.0, stop_time);
    const double f = stop_time > 0 ? s - 0.5 * s * s / stop_time : 0.0;
    return start + velocity * f;
  }
  Vec3 velocity_at(double t) const {
    const double s = std::clamp(t, 0.0, stop_time);
    return stop_time > 0 ? Vec3(velocity * (1.0 - s / stop_time)) : Vec3(Vec3::Zero());
  }
  Vec3 acceleration_at(double t) const {
    return (t >= 0 && t < stop_time) ? Vec3(-velocity / stop_time) : Vec3::Zero();
  }
};

/// The stop from (position, velocity) at `deceleration` (a non-finite or
/// non-positive deceleration brakes at 1 m/s^2 rather than not at all).
inline StopProfile stop_from(const Vec3& position, const Vec3& velocity, double deceleration) {
  StopProfile stop;
  stop.start = position;
  stop.deceleration = std::isfinite(deceleration) && deceleration > 1e-6 ? deceleration : 1.0;
  const double speed = velocity.norm();
  if (std::isfinite(speed) && speed > kHoverSpeed) {
    stop.velocity = velocity;
    stop.stop_time = speed / stop.deceleration;
  }
  return stop;
}

}  // namespace ofn
