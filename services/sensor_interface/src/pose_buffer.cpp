#include "ofn/sensor_interface/pose_buffer.hpp"

#include <algorithm>
#include <stdexcept>

namespace ofn::sensing {

PoseBuffer::PoseBuffer(double history, double max_extrapolation)
    : history_(to_utime(history)), max_extrapolation_(to_utime(max_extrapolation)) {
  if (!(history > 0)) throw std::invalid_argument("pose history must be > 0 s");
  if (!(max_extrapolation >= 0))
    throw std::invalid_argument("pose max_extrapolation must be >= 0 s");
}

bool PoseBuffer::insert(const Pose& sample) {
  if (!samples_.empty() && sample.utime <= samples_.back().utime) return false;
  samples_.push_back(sample);
  samples_.back().attitude.normalize();
  // Keep the sample at or before (newest - history) so that the whole
  // history span can still be interpolated.
  const Utime keep_from = sample.utime - history_;
  while (samples_.size() >= 2 && samples_[1].utime <= keep_from) samples_.pop_front();
  return true;
}

std::optional<Pose> PoseBuffer::interpolate(Utime t) const {
  if (samples_.empty() || t < samples_.front().utime) return std::nullopt;
  const Pose& last = samples_.back();
  if (t >= last.utime) {
    if (t - last.utime > max_extrapolation_) return std::nullopt;
    Pose p = last;
    p.utime = t;
    p.position += last.velocity * to_seconds(t - last.utime);
    return p;
  }
  // First sample newer than t; it exists and is not the first one.
  const auto after = std::upper_bound(samples_.begin(), samples_.end(), t,
                                      [](Utime time, const Pose& s) { return time < s.utime; });
  const Pose& b = *after;
  const Pose& a = *(after - 1);
  const double f = static_cast<double>(t - a.utime) / static_cast<double>(b.utime - a.utime);
  Pose p;
  p.utime = t;
  p.position = a.position + f * (b.position - a.position);
  p.velocity = a.velocity + f * (b.velocity - a.velocity);
  p.attitude = a.attitude.slerp(f, b.attitude);
  return p;
}

std::optional<Pose> PoseBuffer::newest() const {
  if (samples_.empty()) return std::nullopt;
  return samples_.back();
}

std::optional<Pose> PoseBuffer::oldest() const {
  if (samples_.empty()) return std::nullopt;
  return samples_.front();
}

}  // namespace ofn::sensing
