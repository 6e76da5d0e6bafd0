#pragma once
// Guards a clock that follows SIM_CLOCK messages against a time source that
// jumps. One message stamped far ahead would otherwise make every timer of a
// following service fire up to its catch-up bound at once and then leave the
// service waiting for a time the real simulation reaches much later; one
// stamped behind would stop its timers until the simulation caught up again.
// Both are refused. A source that really did move to another timeline (a
// restarted simulation) is followed once it has kept to that timeline for
// `resync_after` seconds of its own time and `resync_after_wall` seconds of
// arrival time, without a stamp from the old one in between: the arrival
// time is what a forger cannot write, so a burst of forged stamps that span
// the resync time in a few milliseconds is never followed.

#include <string>

#include "ofn/common/clock.hpp"

namespace ofn {

struct SimClockGuardLimits {
  /// Largest step ahead accepted, s: SIM_CLOCK comes at 100 Hz, so a second
  /// is a hundred lost messages.
  double max_forward = 1.0;
  /// Time another timeline must be kept, s of its own time, before it is
  /// followed; the old timeline's messages restart the wait.
  double resync_after = 2.0;
  /// And s of arrival time (a monotonic wall clock).
  double resync_after_wall = 1.0;
};

class SimClockGuard {
 public:
  enum class Verdict {
    kAccepted,  ///< follow it
    kRejected,  ///< ignore it; reason() says why
    kResynced,  ///< follow it: a new timeline; timers must start afresh
  };

  explicit SimClockGuard(SimClockGuardLimits limits = {});

  /// Judges the stamp of one SIM_CLOCK message that arrived at `arrival`
  /// (a monotonic wall time, us). Stamps are never negative (validate()).
  Verdict offer(Utime stamp, Utime arrival);
  /// Why the last stamp was rejected ("jumps ahead by 999.99 s").
  const std::string& reason() const { return reason_; }
  /// The time followed; INT64_MIN before the first stamp.
  Utime followed() const { return followed_; }

 private:
  SimClockGuardLimits limits_;
  Utime followed_ = INT64_MIN;
  // Another timeline seen since the last accepted stamp: its first and last.
  Utime candidate_first_ = INT64_MIN;
  Utime candidate_last_ = INT64_MIN;
  Utime candidate_first_arrival_ = INT64_MIN;
  std::string reason_;
};

}  // namespace ofn
