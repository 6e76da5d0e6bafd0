#pragma once
// The stop every plan carries: from a reference state, decelerate along the
// velocity to a hover, then hold there. The RH optimiser checks this stop
// before it commits a plan, and the controller flies the same stop when the
// plans stop coming, so what was checked is what is flown. Pure,
// header-only, SI units, world NED.
//
// The deceleration is constant and then, over the last `ramp_time`, eases
// linearly to zero. The vehicle's tilt lags its command by a few tenths of
// a second, so a reference that stops decelerating quickly leaves it still
// tilted back: it overshoots into a reverse drift, which the forward-speed
// rule of Eq. 8 counts (2 % of the speed limit, 6 cm/s on the benchmarks).
// Flown by the controller and the simulated airframe with the shipped
// settings, from 0.6-3 m/s and 0-63 deg off the heading under the yaw sweep
// (test_stop_flown.cpp), the worst reverse drift at 0.39 m/s^2 is 12 cm/s
// with a 0.8 s ease-out, 7 cm/s with 1.6 s and 1.4 cm/s with 2.4 s. The
// ease-out costs deceleration * ramp_time^2 / 24 of extra distance (9 cm at
// the benchmarks' 0.39 m/s^2 and 2.4 s) and ramp_time / 2 of extra time. A
// stop too slow to reach full deceleration is all ease-out, at the same
// jerk.

#include <algorithm>
#include <cmath>

#include "ofn/common/frames.hpp"

namespace ofn {

/// Below this speed (m/s) a state counts as a hover: no braking piece.
constexpr double kHoverSpeed = 1e-3;

/// s over which a stop's deceleration eases to zero (at full deceleration).
constexpr double kStopRampTime = 2.4;

struct StopProfile {
  Vec3 start = Vec3::Zero();     // m, world NED
  Vec3 velocity = Vec3::Zero();  // m/s at the start
  double deceleration = 1.0;     // m/s^2, > 0: the constant part's
  double peak_deceleration = 0;  // m/s^2 reached (below `deceleration` on a short stop)
  double constant_time = 0;      // s at peak_deceleration
  double ramp_time = 0;          // s of the ease-out that follows
  double stop_time = 0;          // s to the hover: constant_time + ramp_time

  Vec3 direction() const {
    const double speed = velocity.norm();
    return speed > 0 ? Vec3(velocity / speed) : Vec3(Vec3::Zero());
  }
  /// Distance along the stop, speed and deceleration `t` s after the start.
  double distance_at(double t) const {
    const double v0 = velocity.norm(), a = peak_deceleration;
    const double s = std::clamp(t, 0.0, constant_time);
    double d = v0 * s - 0.5 * a * s * s;
    if (t > constant_time && ramp_time > 0) {
      const double v1 = v0 - a * constant_time;
      const double u = std::min(t, stop_time) - constant_time;
      d += v1 * u - 0.5 * a * u * u + a * u * u * u / (6.0 * ramp_time);
    }
    return d;
  }
  double speed_at(double t) const {
    if (t >= stop_time) return 0.0;
    const double v0 = velocity.norm(), a = peak_deceleration;
    if (t <= constant_time) return v0 - a * std::max(0.0, t);
    const double u = t - constant_time;
    return std::max(0.0, v0 - a * constant_time - a * u + 0.5 * a * u * u / ramp_time);
  }
  double deceleration_at(double t) const {
    if (t < 0 || t >= stop_time) return 0.0;
    if (t <= constant_time) return peak_deceleration;
    return peak_deceleration * (1.0 - (t - constant_time) / ramp_time);
  }

  Vec3 stop_point() const { return start + direction() * distance(); }
  double distance() const { return distance_at(stop_time); }
  /// State `t` seconds after the start (held at the hover afterwards).
  Vec3 position(double t) const { return start + direction() * distance_at(t); }
  Vec3 velocity_at(double t) const { return direction() * speed_at(t); }
  Vec3 acceleration_at(double t) const { return -direction() * deceleration_at(t); }
};

/// The stop from (position, velocity) at `deceleration` (a non-finite or
/// non-positive deceleration brakes at 1 m/s^2 rather than not at all),
/// easing out over `ramp_time` (0: a step to the hover).
inline StopProfile stop_from(const Vec3& position, const Vec3& velocity, double deceleration,
                             double ramp_time = kStopRampTime) {
  StopProfile stop;
  stop.start = position;
  stop.deceleration = std::isfinite(deceleration) && deceleration > 1e-6 ? deceleration : 1.0;
  const double speed = velocity.norm();
  if (!(std::isfinite(speed) && speed > kHoverSpeed)) return stop;
  stop.velocity = velocity;
  const double a = stop.deceleration;
  const double ramp = std::isfinite(ramp_time) && ramp_time > 0 ? ramp_time : 0.0;
  if (ramp == 0) {
    stop.peak_deceleration = a;
    stop.constant_time = speed / a;
  } else if (speed >= 0.5 * a * ramp) {
    stop.peak_deceleration = a;
    stop.constant_time = speed / a - 0.5 * ramp;
    stop.ramp_time = ramp;
  } else {
    // All ease-out at the full stop's jerk a / ramp: the speed it sheds,
    // peak^2 / (2 jerk), is the whole speed.
    const double jerk = a / ramp;
    stop.peak_deceleration = std::sqrt(2.0 * speed * jerk);
    stop.ramp_time = stop.peak_deceleration / jerk;
  }
  stop.stop_time = stop.constant_time + stop.ramp_time;
  return stop;
}

}  // namespace ofn
