#include "ofn/common/sim_clock_guard.hpp"

#include <cstdio>
#include <stdexcept>

namespace ofn {
namespace {

std::string seconds_text(const char* what, Utime step) {
  char text[64];
  std::snprintf(text, sizeof text, "%s by %.3f s", what, to_seconds(step));
  return text;
}

}  // namespace

SimClockGuard::SimClockGuard(SimClockGuardLimits limits) : limits_(limits) {
  if (!(limits_.max_forward > 0) || !(limits_.resync_after >= 0) ||
      !(limits_.resync_after_wall >= 0))
    throw std::invalid_argument(
        "SimClockGuard: max_forward must be > 0, resync_after and resync_after_wall >= 0");
}

SimClockGuard::Verdict SimClockGuard::offer(Utime stamp, Utime arrival) {
  const Utime max_step = to_utime(limits_.max_forward);
  if (followed_ == INT64_MIN || (stamp >= followed_ && stamp - followed_ <= max_step)) {
    followed_ = stamp;
    candidate_first_ = candidate_last_ = INT64_MIN;
    return Verdict::kAccepted;
  }
  reason_ = stamp > followed_ ? seconds_text("jumps ahead", stamp - followed_)
                              : seconds_text("goes back", followed_ - stamp);
  // Does it continue the other timeline seen since the last accepted stamp?
  const bool continues = candidate_last_ != INT64_MIN && stamp >= candidate_last_ &&
                         stamp - candidate_last_ <= max_step;
  if (!continues) {
    candidate_first_ = stamp;
    candidate_first_arrival_ = arrival;
  }
  candidate_last_ = stamp;
  if (candidate_last_ - candidate_first_ >= to_utime(limits_.resync_after) &&
      arrival - candidate_first_arrival_ >= to_utime(limits_.resync_after_wall)) {
    followed_ = stamp;
    candidate_first_ = candidate_last_ = INT64_MIN;
    return Verdict::kResynced;
  }
  return Verdict::kRejected;
}

}  // namespace ofn
