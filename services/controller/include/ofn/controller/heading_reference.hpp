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
///
/// The paper's sweep (+-20 deg) suits a vehicle that faces where it flies.
/// Slower than the path heading's min_speed it does not: the heading holds
/// while the vehicle creeps, stops and sets off sideways, and the space
/// beside it that a stop or a turn could enter lies outside +-20 deg (dense
/// fields: a cylinder 60 deg off the path of a vehicle creeping at 1 m/s,
/// mapped only once it was 3.8 m away). So a slow vehicle sweeps wider
/// (wide_total_angle), the frequency dropping so that the peak yaw rate stays
/// the nominal one.
struct YawSweep {
  bool enabled = true;
  double frequency = 0.2;            // Hz
  double total_angle = deg2rad(40);  // rad, peak to peak, at cruise
  double scanner_timeout = 1.0;      // s with no SCANNER_STATUS: the scanner counts as off
  /// rad, peak to peak, at the widest (hovering); total_angle: never widens.
  double wide_total_angle = deg2rad(120);
  double widen_rate = deg2rad(10);  // rad/s the half angle changes at most once faded in
  /// Widen the sweep (up to cover_total_angle) so that the scan plane
  /// reaches the clearance R_s beside the path at the distance the vehicle
  /// needs to stop (SweepCoverage). At cruise on the benchmarks' limits that
  /// is +-27 deg: +-20 deg reaches only 4.3 m to the side at the 12 m
  /// stopping distance, and a dense field's cylinder 4.5 m beside a turning
  /// path was never scanned (seed 23, docs/RESULTS.md).
  bool cover_clearance = true;
  /// rad, peak to peak: the widest that rule makes the sweep. Between 1 and
  /// 2.5 m/s the rule asks for up to +-60 deg; swept that wide at speed,
  /// where the adaptive element learns, the inner loop went into a roll
  /// and pitch limit cycle of +-25 deg (dense seed 13). Slower than
  /// min_speed the sweep is wide_total_angle whatever this is.
  double cover_total_angle = deg2rad(60);
};

/// What the sweep keeps in view (YawSweep::cover_clearance): `clearance` m
/// to either side of the path at the stopping distance from the vehicle's
/// speed at `deceleration` m/s^2 (the stop of braking.hpp without its
/// onset). A zero or non-finite entry: no such rule.
struct SweepCoverage {
  double clearance = 0;     // m
  double deceleration = 0;  // m/s^2
};

/// Half angle (rad) of the sweep for a vehicle at horizontal `speed`: the
/// wide one below `slow_speed` (the path heading's min_speed), else the
/// nominal one, or wider, up to cover_total_angle, as `coverage` asks.
double sweep_half_angle(const YawSweep& sweep, double speed, double slow_speed,
                        const SweepCoverage& coverage);

/// The sweep's yaw offset over time: a(t) sin(phi(t)). The half angle a
/// ramps from zero to the nominal one over one period (the commanded yaw and
/// its rate start at zero), then follows the target half angle at up to
/// widen_rate, smoothly (its own rate changes gradually);
/// the phase advances at 2 pi frequency, slowed where a exceeds the nominal
/// half angle so that the peak yaw rate a phi' stays the nominal sweep's.
class YawSweepGenerator {
 public:
  explicit YawSweepGenerator(YawSweep sweep = {}) : sweep_(sweep) {}
  /// Back to zero amplitude and phase (the scanner started, or restarted).
  void restart();
  /// One step of `dt` s toward `target_half_angle` (rad); returns the yaw
  /// offset and writes its rate to `rate`.
  double update(double target_half_angle, double dt, double* rate);
  /// The same step toward the half angle its own settings give a vehicle
  /// at horizontal `speed` (sweep_half_angle).
  double update_at_speed(double speed, double slow_speed, const SweepCoverage& coverage, double dt,
                         double* rate) {
    return update(sweep_half_angle(sweep_, speed, slow_speed, coverage), dt, rate);
  }
  double half_angle() const { return half_; }

 private:
  /// s within which the half angle heads for a new target.
  static constexpr double kWidenSettle = 1.0;
  YawSweep sweep_;
  double half_ = 0;       // rad
  double half_rate_ = 0;  // rad/s
  double phase_ = 0;      // rad
  bool faded_in_ = false;
};

/// How the vehicle faces along its path. A trajectory's velocity turns fast
/// when it is slow (a stop beside the waypoint turns it through tens of
/// degrees in a second), and a mode or leg change steps the path direction
/// (a route flown back turns it through 180 deg at once): the heading follows
/// at a bounded rate and a bounded yaw acceleration, and holds below a speed.
struct PathHeading {
  double max_rate = deg2rad(30);  // rad/s the path heading turns at most
  /// rad/s^2 the turn rate changes at most. A turn rate that steps (0 to
  /// 30 deg/s in one step) gives the inner loop a yaw-rate step; during a
  /// sideways stop that swings the flown velocity by 0.2 m/s across the
  /// stop, and the inner adaptive element, learning from the transient,
  /// diverged in simulation (test_stop_flown.cpp).
  double max_accel = deg2rad(60);
  double min_speed = 1.0;  // m/s of reference velocity below which it holds
  /// s ahead along a trajectory the vehicle faces: the scanner looks where
  /// the plan is going, not only where it goes now, so that the space a
  /// turning plan (and its stops) will enter has been seen before it gets
  /// there. 0 faces along the velocity.
  double look_ahead = 3.0;
};

/// The path heading: a double integrator driven toward the direction to
/// face, its turn rate within max_rate and changing by at most
/// max_accel * dt per step, slowing in time to stop on the direction (no
/// overshoot beyond a step's worth). Its turn rate is its own smooth state,
/// so it is fed forward; the direction itself (a sampled reference's,
/// jumping a little with every new trajectory) is never differentiated.
class PathHeadingFilter {
 public:
  explicit PathHeadingFilter(PathHeading settings = {}) : settings_(settings) {}

  /// Starts from `yaw` (the vehicle's heading when control begins, in
  /// (-pi, pi]).
  void reset(double yaw);
  bool initialised() const { return initialised_; }
  /// One step: turn toward the horizontal direction `facing`, or, without
  /// one (hovering, climbing straight up), bring the turn to a stop and hold
  /// the heading. Returns the path heading in (-pi, pi].
  double update(const std::optional<Vec3>& facing, double dt);
  double yaw() const { return yaw_; }
  /// rad/s the heading turns at now (within max_rate, changing at most
  /// max_accel per second). Fed forward, it removes the lag a turn otherwise
  /// leaves (7 deg at 30 deg/s), which the inner loop's adaptive element
  /// would learn from.
  double turn_rate() const { return turn_rate_; }

 private:
  PathHeading settings_;
  double yaw_ = 0;
  double turn_rate_ = 0;
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
/// `yaw` (to the left with `left`), so that the path heading, always turning
/// toward it, turns at its full rate for as long as the look lasts.
Vec3 look_around_facing(double yaw, bool left = false);

}  // namespace ofn::control
