#pragma once
// Reading a REF_TRAJ: its B-spline, its samples, and its state at a time.
// The RH optimiser sends a plan as its B-spline alone (knots and control
// points: one datagram, where 200 samples made ten, and a message is lost
// with any of its datagrams); every receiver first expands it into samples
// every kRefTrajSamplePeriod (expand_ref_traj), so that what it flies,
// checks and draws is the same table of samples a sender may also send.

#include <optional>

#include "ofn/common/bspline.hpp"
#include "ofn/common/frames.hpp"
#include "ofn/ref_traj_t.hpp"

namespace ofn {

/// s between the samples a receiver makes of a plan sent as its spline.
constexpr double kRefTrajSamplePeriod = 0.1;

struct RefTrajSample {
  Vec3 position = Vec3::Zero();      // m, world NED
  Vec3 velocity = Vec3::Zero();      // m/s
  Vec3 acceleration = Vec3::Zero();  // m/s^2
};

/// The plan's state `t` seconds after its t0, by linear interpolation of
/// its samples; nullopt outside its sampled span (or with fewer than two
/// samples). The message must have passed validate().
std::optional<RefTrajSample> sample_ref_traj_at(const ref_traj_t& traj, double t);

/// The B-spline a message carries (knots in seconds from t0, clamped;
/// control points world NED); nullopt when it carries none. The message
/// must have passed validate().
std::optional<BsplineTrajectory> ref_traj_spline(const ref_traj_t& traj);

/// Replaces `traj`'s samples with `spline` sampled every `period` seconds
/// from 0 to its end, the end included.
void set_ref_traj_samples(ref_traj_t& traj, const BsplineTrajectory& spline, double period);

/// A validated plan sent as its spline alone gets its samples every
/// `period` seconds; one with samples is left as it is.
void expand_ref_traj(ref_traj_t& traj, double period = kRefTrajSamplePeriod);

}  // namespace ofn
