#pragma once
// The flight envelope of Eq. 8 as shares of the mission's limits: the speed,
// the vertical speed and the acceleration (an ellipse whose axes are all
// limits.max_accel, so the norm). A share above 1 + the stated tolerance is
// out of the envelope. One definition for everything that checks a
// reference against the limits: the RH optimiser's commit gate and the
// controller's command gate. Pure, header-only, SI.

#include <algorithm>
#include <cmath>
#include <limits>

#include "ofn/common/frames.hpp"
#include "ofn/common/mission_types.hpp"

namespace ofn {

/// The benchmarks' tolerance over a limit (2 %).
constexpr double kEnvelopeTolerance = 0.02;

struct EnvelopeShares {
  double speed = 0;
  double vertical_speed = 0;
  double acceleration = 0;
  /// The largest share; NaN if any share is NaN.
  double worst() const {
    if (std::isnan(speed) || std::isnan(vertical_speed) || std::isnan(acceleration))
      return std::numeric_limits<double>::quiet_NaN();
    return std::max({speed, vertical_speed, acceleration});
  }
  /// NaN counts as outside.
  bool within(double tolerance) const {
    const double over = 1.0 + tolerance;
    return speed <= over && vertical_speed <= over && acceleration <= over;
  }
};

inline EnvelopeShares envelope_shares(const Vec3& velocity, const Vec3& acceleration,
                                      const Limits& limits) {
  EnvelopeShares s;
  s.speed = velocity.norm() / limits.max_speed;
  s.vertical_speed = std::abs(velocity.z()) / limits.max_vertical_speed;
  s.acceleration = acceleration.norm() / limits.max_accel;
  return s;
}

}  // namespace ofn
