#pragma once
// The state a REF_TRAJ gives at a time, by linear interpolation of its
// samples: what the controller flies, and what the viewer draws the
// controller's stop from.

#include <optional>

#include "ofn/common/frames.hpp"
#include "ofn/ref_traj_t.hpp"

namespace ofn {

struct RefTrajSample {
  Vec3 position = Vec3::Zero();      // m, world NED
  Vec3 velocity = Vec3::Zero();      // m/s
  Vec3 acceleration = Vec3::Zero();  // m/s^2
};

/// The plan's state `t` seconds after its t0; nullopt outside its sampled
/// span (or with fewer than two samples). The message must have passed
/// validate().
std::optional<RefTrajSample> sample_ref_traj_at(const ref_traj_t& traj, double t);

}  // namespace ofn
