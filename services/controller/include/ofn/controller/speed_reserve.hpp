#pragma once
// A speed reserve sized by the disturbance the vehicle meets. The speed
// governor (TrajectoryController::set_speed_limits) bounds what the
// controller asks for, not what a gust adds: in calm air the flown speed
// strays from the reference by a few hundredths of a m/s, in turbulence by
// tenths (the windy test course: an RMS velocity error of 0.45-0.7 m/s,
// the ground speed swinging 7-11.5 ft/s against a 10 ft/s limit). Flying
// at the limit leaves no room for the next gust, so the governor and the
// guidance cruise keep back 1.5 RMS of the velocity tracking error once it
// rises clearly above what calm flight shows, but never so much that the
// vehicle crawls in the wind (slow flight in strong wind lost control);
// below `onset` they keep back nothing, so calm flights are not slowed.
// Pure core: SI units, the caller's time steps.

#include "ofn/common/frames.hpp"

namespace ofn::control {

struct SpeedReserveSettings {
  bool enabled = true;
  /// s; time constant of the running mean square of the velocity error.
  double time_constant = 10.0;
  /// m/s RMS at or below which nothing is kept back. Calm flights measured
  /// 0.04-0.15 (the seven courses, dense fields' braking and turning).
  double onset = 0.25;
  /// m/s RMS from which the whole reserve (sigmas x RMS) is kept back; in
  /// between it grows smoothly, so the governed speed never steps.
  double full = 0.45;
  /// Reserve once full, in RMS of the velocity error.
  double sigmas = 1.5;
  /// Most of the speed limit the reserve may take (the vehicle must still
  /// make way against the wind).
  double max_fraction = 0.35;
};

class SpeedReserve {
 public:
  explicit SpeedReserve(SpeedReserveSettings settings = {}) : settings_(settings) {}

  /// Feeds one step's velocity error (vehicle - reference flown, m/s) over
  /// dt seconds. Non-finite errors and steps are ignored.
  void update(const Vec3& velocity_error, double dt);
  /// m/s, RMS of the velocity error over about the time constant.
  double rms() const;
  /// m/s to keep back from a speed limit of `max_speed` (m/s; <= 0: none).
  double reserve(double max_speed) const;
  /// Forgets what it has measured.
  void reset() { mean_square_ = 0.0; }
  const SpeedReserveSettings& settings() const { return settings_; }

 private:
  SpeedReserveSettings settings_;
  double mean_square_ = 0.0;  // m^2/s^2, running mean started from calm
};

}  // namespace ofn::control
