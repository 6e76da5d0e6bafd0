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
//
// A step ahead after this process heard no stamp for a while (it was
// stopped, starved of CPU, or its link was cut) is no forgery when it is no
// longer than the time the simulation could have run meanwhile: the rate
// measured before, times `gap_rate_margin`, over the silence, plus
// `max_forward`. It is followed at once. Waiting for the resync instead
// froze a service stopped for 3 s for 2 s more, and the launcher's hang
// watch (5 s) restarted it.

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
  /// Arrival time without an accepted stamp, s, that counts as a silence
  /// (SIM_CLOCK comes every 10 ms of simulated time).
  double gap_wall = 0.5;
  /// Share of the measured rate a silence may have run at most, above 1 for
  /// the rate's own jitter.
  double gap_rate_margin = 1.25;
};

class SimClockGuard {
 public:
  enum class Verdict {
    kAccepted,  ///< follow it
    kRejected,  ///< ignore it; reason() says why
    kResynced,  ///< follow it: a new timeline; timers must start afresh
    kCaughtUp,  ///< follow it: the time that ran on while this process heard
                ///< nothing (reason() says how far and how long)
  };

  explicit SimClockGuard(SimClockGuardLimits limits = {});

  /// Judges the stamp of one SIM_CLOCK message that arrived at `arrival`
  /// (a monotonic wall time, us). Stamps are never negative (validate()).
  Verdict offer(Utime stamp, Utime arrival);
  /// Why the last stamp was rejected ("jumps ahead by 999.99 s").
  const std::string& reason() const { return reason_; }
  /// Simulated seconds per second of arrival time, measured over 0.5-2 s
  /// spans of accepted stamps; 0 before the first span.
  double rate() const { return rate_; }
  /// The time followed; INT64_MIN before the first stamp.
  Utime followed() const { return followed_; }

 private:
  /// Follows `stamp`; `step_counts` false for a step that is no sample of
  /// the rate (a silence caught up, a new timeline).
  void accept(Utime stamp, Utime arrival, bool step_counts = true);
  /// The arrival that began the silence `stamp` would end (this one's, or
  /// one that ended under a second ago); INT64_MIN when there is none.
  Utime silence_began(Utime arrival, Utime* stamp_before) const;

  SimClockGuardLimits limits_;
  Utime followed_ = INT64_MIN;
  Utime followed_arrival_ = INT64_MIN;
  // The rate: the start of the span it is measured over, and the estimate.
  Utime rate_from_stamp_ = INT64_MIN;
  Utime rate_from_arrival_ = INT64_MIN;
  double rate_ = 0.0;
  // The last silence among accepted stamps: the stamp and arrival before
  // it, and the arrival that ended it. Stamps queued during the silence
  // (an open bus keeps them) may end it before the step ahead arrives.
  Utime silence_stamp_ = INT64_MIN;
  Utime silence_arrival_ = INT64_MIN;
  Utime silence_end_ = INT64_MIN;
  // Another timeline seen since the last accepted stamp: its first and last.
  Utime candidate_first_ = INT64_MIN;
  Utime candidate_last_ = INT64_MIN;
  Utime candidate_first_arrival_ = INT64_MIN;
  std::string reason_;
};

}  // namespace ofn
