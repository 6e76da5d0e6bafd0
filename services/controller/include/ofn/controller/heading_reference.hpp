#pragma once
// The commanded heading: the vehicle faces along its path, turning at a
// bounded rate, with the oscillatory yaw sweep of the vertical scanner laid
// over it. Pure core: radians and seconds, no LCM; the controller service and
// the in-process tracking flight both build their yaw reference from it.

#include <optional>

#include "ofn/common/frames.hpp"

namespace ofn::control {

/// Oscillatory yaw that sweeps the vertical scanner across the path (paper
/// section 3.1). It runs only while LIDAR scans arrive, and fades in over one
/// period so that the yaw rate never steps.
struct YawSweep {
  bool enabled = true;
  double frequency = 0.2;            // Hz
  double total_angle = deg2rad(40);  // rad, peak to peak
  double scanner_timeout = 1.0;      // s without LIDAR_RAW after which the scanner counts as off
};

/// How the vehicle faces along its path. A trajectory's velocity turns fast
/// when it is slow (a stop beside the waypoint turns it through tens of
/// degrees in a second), and a mode or leg change steps the path direction
/// (a route flown back turns it through 180 deg at once): the heading follows
/// at a bounded rate and holds below a speed.
struct PathHeading {
  double max_rate = deg2rad(30);  // rad/s the path heading turns at most
  double min_speed = 1.0;         // m/s of reference velocity below which it holds
  /// s ahead along a trajectory the vehicle faces: the scanner looks where
  /// the plan is going, not only where it goes now, so that the space a
  /// turning plan (and its stops) will enter has been seen before it gets
  /// there. 0 faces along the velocity.
  double look_ahead = 3.0;
};

/// The path heading, turned toward the direction to face by at most
/// max_rate * dt per step. It gives no yaw-rate feed-forward: the direction
/// of a sampled reference jumps a little with every new trajectory, and its
/// difference quotient would be noise.
class PathHeadingFilter {
 public:
  explicit PathHeadingFilter(PathHeading settings = {}) : settings_(settings) {}

  /// Starts from `yaw` (the vehicle's heading when control begins, in
  /// (-pi, pi]).
  void reset(double yaw);
  bool initialised() const { return initialised_; }
  /// One step: turn toward the horizontal direction `facing`, or hold the
  /// heading without one (hovering, climbing straight up). Returns the
  /// path heading in (-pi, pi].
  double update(const std::optional<Vec3>& facing, double dt);
  double yaw() const { return yaw_; }

 private:
  PathHeading settings_;
  double yaw_ = 0;
  bool initialised_ = false;
};

/// A unit leg direction whose horizontal part is shorter than this is a
/// (nearly) vertical leg: there is no direction along it to face.
constexpr double kMinLegHorizontal = 0.2;

/// `direction` as the one to face when its horizontal part is longer than
/// `min_horizontal`, else none (the heading holds): a vertical leg, or a
/// reference velocity too slow to point anywhere.
std::optional<Vec3> facing_along(const Vec3& direction, double min_horizontal);

/// The direction to face along a trajectory: toward `ahead` (the reference's
/// position look_ahead seconds on, where the plan covers it) from `here`,
/// or along `velocity` without one; none when the reference is slower than
/// `min_speed` (the heading holds).
std::optional<Vec3> facing_ahead(const Vec3& here, const Vec3& velocity,
                                 const std::optional<Vec3>& ahead, double min_speed);

/// The direction to face for a look-around: a quarter turn to the right of
/// `yaw`, so that the path heading, always turning toward it, turns at its
/// full rate for as long as the look lasts.
Vec3 look_around_facing(double yaw);

/// The sweep's yaw offset `t` seconds after it started: a(t) sin(w t) with
/// the amplitude a ramping linearly from zero over one period, so that the
/// commanded yaw and its rate start at zero. `rate` receives its derivative.
double yaw_sweep_offset(const YawSweep& sweep, double t, double* rate);

}  // namespace ofn::control
