#include "ofn/common/sequence_tracker.hpp"

#include <algorithm>
#include <climits>

namespace ofn {
namespace {

// a + b for counters, stopping at INT64_MAX: a forged sequence near 2^64
// must not wrap the count of lost messages.
int64_t saturating_add(int64_t a, uint64_t b) {
  const auto room = static_cast<uint64_t>(INT64_MAX - a);
  return b >= room ? INT64_MAX : a + static_cast<int64_t>(b);
}

}  // namespace

SequenceTracker::SequenceTracker(size_t max_publishers)
    : max_publishers_(std::max<size_t>(1, max_publishers)) {
  publishers_.reserve(max_publishers_);
}

SequenceTracker::Arrival SequenceTracker::on_unsequenced() {
  ++counts_.received;
  ++counts_.unsequenced;
  return Arrival::kUnsequenced;
}

SequenceTracker::Arrival SequenceTracker::on_sequenced(uint64_t publisher, uint64_t sequence) {
  ++counts_.received;
  ++tick_;
  auto it = std::find_if(publishers_.begin(), publishers_.end(),
                         [publisher](const Publisher& p) { return p.id == publisher; });
  if (it == publishers_.end()) {
    if (publishers_.size() >= max_publishers_) {
      // The one heard longest ago makes room (a publisher that went away).
      it = std::min_element(
          publishers_.begin(), publishers_.end(),
          [](const Publisher& a, const Publisher& b) { return a.heard < b.heard; });
    } else {
      it = publishers_.insert(publishers_.end(), Publisher{});
    }
    // Its earlier numbers were never counted lost: one of them arriving now
    // was overtaken, it fills no gap.
    *it = Publisher{publisher, sequence, ~uint64_t{0}, tick_};
    ++counts_.publishers;
    return Arrival::kFirst;
  }
  Publisher& p = *it;
  p.heard = tick_;
  if (sequence > p.highest) {
    const uint64_t step = sequence - p.highest;
    p.seen = step >= kWindow ? 1 : (p.seen << step) | 1;
    p.highest = sequence;
    if (step == 1) return Arrival::kNext;
    counts_.lost = saturating_add(counts_.lost, step - 1);
    return Arrival::kAfterGap;
  }
  ++counts_.duplicated;
  const uint64_t below = p.highest - sequence;
  if (below >= kWindow) return Arrival::kDuplicate;
  const uint64_t bit = uint64_t{1} << below;
  if (p.seen & bit) return Arrival::kDuplicate;
  p.seen |= bit;
  if (counts_.lost > 0) --counts_.lost;
  return Arrival::kLate;
}

}  // namespace ofn
