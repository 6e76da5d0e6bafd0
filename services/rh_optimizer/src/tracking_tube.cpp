#include "ofn/rh_optimizer/tracking_tube.hpp"

#include <algorithm>
#include <cmath>

namespace ofn::rh {

void TrackingTube::add(double time, const Vec3& position_error) {
  if (!std::isfinite(time) || !position_error.allFinite()) return;
  if (!samples_.empty() && time < samples_.back().first) {
    // Reordered on the link: counted now, so that it still widens the tube
    // (kept longer rather than lost). Far behind: a restarted clock.
    if (samples_.back().first - time > settings_.window)
      samples_.clear();
    else
      time = samples_.back().first;
  }
  const double error = position_error.norm();
  while (!samples_.empty() && samples_.back().second <= error) samples_.pop_back();
  samples_.emplace_back(time, error);
  while (samples_.front().first < time - settings_.window) samples_.pop_front();
}

double TrackingTube::largest_error() const {
  return samples_.empty() ? 0.0 : samples_.front().second;
}

double TrackingTube::extra_clearance() const {
  if (!settings_.enabled) return 0.0;
  return std::clamp(largest_error() - settings_.onset, 0.0, settings_.max_extra);
}

}  // namespace ofn::rh
