#pragma once
// A short, time-ordered history of the vehicle's navigation solution, so that
// each LIDAR beam can be placed with the pose of the instant it was fired
// rather than the pose of whichever NAV_STATE happened to arrive last.

#include <deque>
#include <optional>

#include "ofn/common/time.hpp"
#include "ofn/common/frames.hpp"

namespace ofn::sensing {

/// Vehicle pose at one instant, world NED.
struct Pose {
  Utime utime = 0;
  Vec3 position = Vec3::Zero();
  Vec3 velocity = Vec3::Zero();
  Quat attitude = Quat::Identity();  // body-to-world
};

class PoseBuffer {
 public:
  /// Keeps at least `history` seconds behind the newest sample; answers up to
  /// `max_extrapolation` seconds past it.
  explicit PoseBuffer(double history = 2.0, double max_extrapolation = 0.03);

  /// Adds a sample; false (and nothing changes) when it is not newer than
  /// the newest one, i.e. out of order or a duplicate.
  bool insert(const Pose& sample);

  /// Pose at `t`: position and velocity linear, attitude slerped between the
  /// samples around `t`; past the newest sample, dead reckoning on its
  /// velocity with its attitude held, up to max_extrapolation. nullopt before
  /// the oldest sample or beyond the extrapolation limit.
  std::optional<Pose> interpolate(Utime t) const;

  std::optional<Pose> newest() const;
  std::optional<Pose> oldest() const;
  size_t size() const { return samples_.size(); }
  bool empty() const { return samples_.empty(); }
  void clear() { samples_.clear(); }

  double history() const { return to_seconds(history_); }
  double max_extrapolation() const { return to_seconds(max_extrapolation_); }

 private:
  Utime history_;
  Utime max_extrapolation_;
  std::deque<Pose> samples_;
};

}  // namespace ofn::sensing
