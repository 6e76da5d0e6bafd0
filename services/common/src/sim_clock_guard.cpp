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
      !(limits_.resync_after_wall >= 0) || !(limits_.gap_wall > 0) ||
      !(limits_.gap_rate_margin >= 1))
    throw std::invalid_argument(
        "SimClockGuard: max_forward and gap_wall must be > 0, resync_after and "
        "resync_after_wall >= 0, gap_rate_margin >= 1");
}

void SimClockGuard::accept(Utime stamp, Utime arrival, bool step_counts) {
  // The rate over spans of 0.5 to 2 s of arrival: long enough that a burst
  // read at once does not count as fast, short enough to hold no silence.
  const bool span_ok = step_counts && rate_from_arrival_ != INT64_MIN &&
                       arrival >= rate_from_arrival_ && stamp >= rate_from_stamp_ &&
                       arrival - rate_from_arrival_ <= to_utime(2.0);
  if (!span_ok) {
    rate_from_stamp_ = stamp;
    rate_from_arrival_ = arrival;
  } else if (arrival - rate_from_arrival_ >= to_utime(0.5)) {
    const double sample = static_cast<double>(stamp - rate_from_stamp_) /
                          static_cast<double>(arrival - rate_from_arrival_);
    rate_ = rate_ > 0 ? 0.7 * rate_ + 0.3 * sample : sample;
    rate_from_stamp_ = stamp;
    rate_from_arrival_ = arrival;
  }
  if (followed_arrival_ != INT64_MIN && arrival - followed_arrival_ >= to_utime(limits_.gap_wall)) {
    silence_stamp_ = followed_;
    silence_arrival_ = followed_arrival_;
    silence_end_ = arrival;
  }
  followed_ = stamp;
  followed_arrival_ = arrival;
  candidate_first_ = candidate_last_ = INT64_MIN;
}

Utime SimClockGuard::silence_began(Utime arrival, Utime* stamp_before) const {
  if (followed_arrival_ == INT64_MIN) return INT64_MIN;
  if (arrival - followed_arrival_ >= to_utime(limits_.gap_wall)) {
    *stamp_before = followed_;
    return followed_arrival_;
  }
  if (silence_end_ == INT64_MIN || arrival - silence_end_ > to_utime(1.0)) return INT64_MIN;
  *stamp_before = silence_stamp_;
  return silence_arrival_;
}

SimClockGuard::Verdict SimClockGuard::offer(Utime stamp, Utime arrival) {
  const Utime max_step = to_utime(limits_.max_forward);
  if (followed_ == INT64_MIN || (stamp >= followed_ && stamp - followed_ <= max_step)) {
    accept(stamp, arrival);
    return Verdict::kAccepted;
  }
  // Ahead by no more than the simulation could have run in a silence.
  Utime stamp_before = INT64_MIN;
  const Utime began =
      stamp > followed_ && rate_ > 0 ? silence_began(arrival, &stamp_before) : INT64_MIN;
  if (began != INT64_MIN &&
      to_seconds(stamp - stamp_before) <=
          limits_.max_forward + limits_.gap_rate_margin * rate_ * to_seconds(arrival - began)) {
    char text[96];
    std::snprintf(text, sizeof text, "jumps ahead by %.3f s after a silence of %.3f s",
                  to_seconds(stamp - followed_), to_seconds(arrival - began));
    reason_ = text;
    accept(stamp, arrival, false);
    return Verdict::kCaughtUp;
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
    accept(stamp, arrival, false);
    return Verdict::kResynced;
  }
  return Verdict::kRejected;
}

}  // namespace ofn
