#pragma once
// What the sequence numbers of one channel's messages say about the link:
// every Node numbers what it publishes on a channel from 1, under a
// publisher id of its own (the sequence trailer, ofn/bus_auth/trailer.hpp),
// and every receiving Node keeps one of these per channel it subscribes to.
//
// For each publisher it holds the highest sequence seen and which of the 63
// before it arrived. A sequence above the highest counts the numbers it
// skips as lost; one at or below it is a copy or was overtaken (counted
// duplicated), and one that fills a gap within the window takes its number
// back out of the lost. A publisher first heard (a receiver that started
// late, a restarted publisher with a new id) counts as new, never its
// earlier numbers as lost. At most `max_publishers` are held per channel;
// a new one beyond that evicts the one heard longest ago (heard again, it
// is new again). A message without a sequence trailer (an older recording,
// a foreign publisher) is counted unsequenced and tells nothing of loss.
//
// Pure: no bus, no clock. Never throws.

#include <cstddef>
#include <cstdint>
#include <vector>

namespace ofn {

/// Counts of one channel since the receiver started.
struct SequenceCounts {
  int64_t received = 0;     ///< every message counted, sequenced or not
  int64_t lost = 0;         ///< numbers skipped, less those that came late
  int64_t duplicated = 0;   ///< at or below the publisher's highest: a copy or overtaken
  int64_t unsequenced = 0;  ///< without a sequence trailer
  int64_t publishers = 0;   ///< publishers first heard (a restart is one more)
};

class SequenceTracker {
 public:
  static constexpr size_t kDefaultMaxPublishers = 8;
  /// How far below its highest a publisher's message is still told apart
  /// as late (filling a gap) or a copy.
  static constexpr uint64_t kWindow = 64;

  /// What one message was.
  enum class Arrival {
    kFirst,        ///< a publisher not held before
    kNext,         ///< the publisher's next number
    kAfterGap,     ///< numbers skipped before it (counted lost)
    kLate,         ///< below the highest, filling a gap (taken out of the lost)
    kDuplicate,    ///< a number already seen, or too far below to tell
    kUnsequenced,  ///< no sequence trailer
  };

  /// `max_publishers` is raised to 1 if below.
  explicit SequenceTracker(size_t max_publishers = kDefaultMaxPublishers);

  /// A message numbered `sequence` by publisher `publisher`.
  Arrival on_sequenced(uint64_t publisher, uint64_t sequence);
  /// A message without a sequence trailer.
  Arrival on_unsequenced();

  const SequenceCounts& counts() const { return counts_; }
  /// Publishers held now (at most max_publishers).
  size_t publishers_held() const { return publishers_.size(); }

 private:
  struct Publisher {
    uint64_t id = 0;
    uint64_t highest = 0;
    uint64_t seen = 0;   // bit i: highest - i arrived
    uint64_t heard = 0;  // tick of the last message, for eviction
  };
  size_t max_publishers_;
  uint64_t tick_ = 0;
  std::vector<Publisher> publishers_;
  SequenceCounts counts_;
};

}  // namespace ofn
