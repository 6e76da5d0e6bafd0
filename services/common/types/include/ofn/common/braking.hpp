#pragma once
// The stop every plan carries: from a reference state, decelerate along the
// velocity to a hover, then hold there. The RH optimiser checks this stop
// before it commits a plan, and the controller flies the same stop when the
// plans stop coming, so what was checked is what is flown. Pure,
// header-only, SI units, world NED.
//
// The acceleration along the velocity goes linearly from the start's to
// the deceleration (the onset, see stop_from), stays there, and over the
// last `ramp_time` eases linearly to zero. The vehicle's tilt lags its
// command by a few tenths of a second, so a reference that stops
// decelerating quickly leaves it still tilted back: it overshoots into a
// reverse drift, which the forward-speed rule of Eq. 8 counts (2 % of the
// speed limit, 6 cm/s on the benchmarks). Flown by the controller and the
// simulated airframe with the shipped settings, from 0.6-3 m/s and 0-63
// deg off the heading under the yaw sweep (test_stop_flown.cpp), the worst
// reverse drift at 0.39 m/s^2 is 12 cm/s with a 0.8 s ease-out, 7 cm/s
// with 1.6 s and 1.4 cm/s with 2.4 s. The ease-out costs deceleration *
// ramp_time^2 / 24 of extra distance (9 cm at the benchmarks' 0.39 m/s^2
// and 2.4 s) and ramp_time / 2 of extra time. A stop too slow to reach
// full deceleration has no constant part; its onset and ease-out keep
// their jerks.

#include <algorithm>
#include <cmath>

#include "ofn/common/frames.hpp"

namespace ofn {

/// Below this speed (m/s) a state counts as a hover: no braking piece.
constexpr double kHoverSpeed = 1e-3;

/// s over which a stop's deceleration eases to zero (at full deceleration).
constexpr double kStopRampTime = 2.4;

/// s over which a stop's deceleration builds up from zero to full; from a
/// reference still speeding up, longer at the same jerk.
constexpr double kStopOnsetTime = 0.6;

struct StopProfile {
  Vec3 start = Vec3::Zero();      // m, world NED
  Vec3 velocity = Vec3::Zero();   // m/s at the start
  double deceleration = 1.0;      // m/s^2, > 0: the constant part's
  double start_acceleration = 0;  // m/s^2 along the velocity at the start (> 0: speeding up)
  double peak_deceleration = 0;   // m/s^2 reached (below `deceleration` on a short stop)
  double onset_time = 0;          // s from the start acceleration to peak_deceleration
  double constant_time = 0;       // s at peak_deceleration
  double ramp_time = 0;           // s of the ease-out that follows
  double stop_time = 0;           // s to the hover: onset_time + constant_time + ramp_time

  Vec3 direction() const {
    const double speed = velocity.norm();
    return speed > 0 ? Vec3(velocity / speed) : Vec3(Vec3::Zero());
  }
  /// Acceleration along the direction (< 0 braking) `t` s after the start.
  double along_acceleration_at(double t) const {
    if (t < 0 || t >= stop_time) return 0.0;
    const double a0 = start_acceleration, p = peak_deceleration;
    if (t < onset_time) return a0 + (-p - a0) * t / onset_time;
    const double u = t - onset_time - constant_time;
    if (u <= 0) return -p;
    return -p * (1.0 - u / ramp_time);
  }
  /// Distance along the stop `t` s after the start.
  double distance_at(double t) const { return along(t).distance; }
  double speed_at(double t) const {
    if (t >= stop_time) return 0.0;
    return std::max(0.0, along(t).speed);
  }
  double deceleration_at(double t) const { return -along_acceleration_at(t); }

  Vec3 stop_point() const { return start + direction() * distance(); }
  double distance() const { return distance_at(stop_time); }
  /// State `t` seconds after the start (held at the hover afterwards).
  Vec3 position(double t) const { return start + direction() * distance_at(t); }
  Vec3 velocity_at(double t) const { return direction() * speed_at(t); }
  Vec3 acceleration_at(double t) const { return direction() * along_acceleration_at(t); }

 private:
  struct Along {
    double distance = 0, speed = 0;
  };
  /// Distance and speed `t` s after the start, phase by phase (each a
  /// cubic in time: linear acceleration).
  Along along(double t) const {
    const double v0 = velocity.norm(), a0 = start_acceleration, p = peak_deceleration;
    t = std::clamp(t, 0.0, stop_time);
    Along at{0.0, v0};
    // Onset: the acceleration from a0 to -p, linearly.
    const double s1 = std::min(t, onset_time);
    if (s1 > 0) {
      const double jerk = (-p - a0) / onset_time;
      at.distance = v0 * s1 + 0.5 * a0 * s1 * s1 + jerk * s1 * s1 * s1 / 6.0;
      at.speed = v0 + a0 * s1 + 0.5 * jerk * s1 * s1;
    }
    // Constant deceleration.
    const double s2 = std::clamp(t - onset_time, 0.0, constant_time);
    at.distance += at.speed * s2 - 0.5 * p * s2 * s2;
    at.speed -= p * s2;
    // Ease-out to the hover.
    const double u = std::clamp(t - onset_time - constant_time, 0.0, ramp_time);
    if (u > 0) {
      at.distance += at.speed * u - 0.5 * p * u * u + p * u * u * u / (6.0 * ramp_time);
      at.speed += -p * u + 0.5 * p * u * u / ramp_time;
    }
    return at;
  }
};

/// The stop from (position, velocity) at `deceleration` (a non-finite or
/// non-positive deceleration brakes at 1 m/s^2 rather than not at all),
/// from `start_acceleration` (the reference's, of which the part along the
/// velocity counts), building up over `onset_time` at full deceleration and
/// easing out over `ramp_time` (0: steps).
///
/// Why the onset: a reference that steps from speeding up to braking leaves
/// the vehicle's tilt behind by its lag; the vehicle overshoots the
/// reference, its controller brakes harder to catch up, and it ends the stop
/// drifting back. Flown with the shipped controller settings from 0.45 m/s
/// while the reference sped up at 0.3 m/s^2 (test_stop_flown.cpp), a
/// stepped stop drifted back by 13 cm/s.
inline StopProfile stop_from(const Vec3& position, const Vec3& velocity,
                             const Vec3& start_acceleration, double deceleration,
                             double ramp_time = kStopRampTime, double onset_time = kStopOnsetTime) {
  StopProfile stop;
  stop.start = position;
  stop.deceleration = std::isfinite(deceleration) && deceleration > 1e-6 ? deceleration : 1.0;
  const double speed = velocity.norm();
  if (!(std::isfinite(speed) && speed > kHoverSpeed)) return stop;
  stop.velocity = velocity;
  const double d = stop.deceleration;
  const double along =
      start_acceleration.allFinite() ? start_acceleration.dot(velocity) / speed : 0;
  // Never beyond the deceleration on either side: a larger start
  // acceleration is not the stop's to carry on.
  const double a0 = std::clamp(along, -d, d);
  const double ramp = std::isfinite(ramp_time) && ramp_time > 0 ? ramp_time : 0.0;
  const double onset = std::isfinite(onset_time) && onset_time > 0 ? onset_time : 0.0;
  const double out_jerk = ramp > 0 ? d / ramp : 0.0;   // 0: a step to the hover
  const double on_jerk = onset > 0 ? d / onset : 0.0;  // 0: a step to -peak
  // The speed shed by the onset to -p and by the ease-out from -p.
  const auto onset_time_to = [&](double p) { return on_jerk > 0 ? (a0 + p) / on_jerk : 0.0; };
  const auto onset_shed = [&](double p) { return -0.5 * (a0 - p) * onset_time_to(p); };
  const auto ramp_shed = [&](double p) { return out_jerk > 0 ? 0.5 * p * p / out_jerk : 0.0; };
  stop.start_acceleration = a0;
  double p = d;
  if (onset_shed(p) + ramp_shed(p) > speed) {
    // Too slow for the full deceleration: the peak that sheds exactly the
    // speed, with no constant part (the shed grows with the peak).
    double lo = on_jerk > 0 ? std::max(0.0, -a0) : 0.0, hi = d;
    if (on_jerk > 0 && onset_shed(lo) + ramp_shed(lo) >= speed) {
      // Already braking hard at the start: ease out from there at once,
      // a little faster than the stop's ease-out.
      stop.start_acceleration = -lo;
      stop.peak_deceleration = lo;
      stop.ramp_time = lo > 0 ? 2.0 * speed / lo : 0.0;
      stop.stop_time = stop.ramp_time;
      return stop;
    }
    for (int i = 0; i < 60; ++i) {
      const double mid = 0.5 * (lo + hi);
      (onset_shed(mid) + ramp_shed(mid) > speed ? hi : lo) = mid;
    }
    p = 0.5 * (lo + hi);
  }
  stop.peak_deceleration = p;
  if (on_jerk == 0) stop.start_acceleration = -p;  // a step to the peak
  stop.onset_time = onset_time_to(p);
  stop.ramp_time = out_jerk > 0 ? p / out_jerk : 0.0;
  stop.constant_time = std::max(0.0, (speed - onset_shed(p) - ramp_shed(p)) / p);
  stop.stop_time = stop.onset_time + stop.constant_time + stop.ramp_time;
  return stop;
}

/// The stop from a state that is not speeding up or slowing down.
inline StopProfile stop_from(const Vec3& position, const Vec3& velocity, double deceleration,
                             double ramp_time = kStopRampTime, double onset_time = kStopOnsetTime) {
  return stop_from(position, velocity, Vec3::Zero(), deceleration, ramp_time, onset_time);
}

}  // namespace ofn
