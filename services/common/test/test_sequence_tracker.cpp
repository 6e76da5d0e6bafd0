// The sequence counter of one channel: gaps are lost, copies and overtaken
// messages duplicated, a late one fills its gap, a new publisher is never
// loss, and its memory is bounded.

#include <gtest/gtest.h>

#include <climits>
#include <cstdint>

#include "ofn/common/sequence_tracker.hpp"

namespace ofn {
namespace {

using Arrival = SequenceTracker::Arrival;

TEST(SequenceTracker, InOrderMessagesLoseNothing) {
  SequenceTracker t;
  EXPECT_EQ(t.on_sequenced(7, 1), Arrival::kFirst);
  for (uint64_t s = 2; s <= 100; ++s) EXPECT_EQ(t.on_sequenced(7, s), Arrival::kNext);
  EXPECT_EQ(t.counts().received, 100);
  EXPECT_EQ(t.counts().lost, 0);
  EXPECT_EQ(t.counts().duplicated, 0);
  EXPECT_EQ(t.counts().publishers, 1);
}

TEST(SequenceTracker, AGapCountsEveryNumberItSkips) {
  SequenceTracker t;
  t.on_sequenced(7, 1);
  t.on_sequenced(7, 2);
  EXPECT_EQ(t.on_sequenced(7, 6), Arrival::kAfterGap);
  EXPECT_EQ(t.counts().lost, 3);
  EXPECT_EQ(t.on_sequenced(7, 7), Arrival::kNext);
  EXPECT_EQ(t.counts().lost, 3);
  EXPECT_EQ(t.counts().received, 4);
}

TEST(SequenceTracker, ACopyIsDuplicatedAndALateOneFillsItsGap) {
  SequenceTracker t;
  t.on_sequenced(7, 1);
  t.on_sequenced(7, 3);  // 2 overtaken by 3
  EXPECT_EQ(t.counts().lost, 1);
  EXPECT_EQ(t.on_sequenced(7, 2), Arrival::kLate);
  EXPECT_EQ(t.counts().lost, 0);
  EXPECT_EQ(t.counts().duplicated, 1);
  // 2 and 3 again: copies, and lost stays.
  EXPECT_EQ(t.on_sequenced(7, 2), Arrival::kDuplicate);
  EXPECT_EQ(t.on_sequenced(7, 3), Arrival::kDuplicate);
  EXPECT_EQ(t.counts().lost, 0);
  EXPECT_EQ(t.counts().duplicated, 3);
  EXPECT_EQ(t.counts().received, 5);
}

TEST(SequenceTracker, BeyondTheWindowALowNumberIsACopyAndTakesNothingBack) {
  SequenceTracker t;
  t.on_sequenced(7, 1);
  t.on_sequenced(7, 200);
  EXPECT_EQ(t.counts().lost, 198);
  // 100 is far below 200: too far to tell.
  EXPECT_EQ(t.on_sequenced(7, 100), Arrival::kDuplicate);
  EXPECT_EQ(t.counts().lost, 198);
  // 190 is within the window and was never seen: it came late.
  EXPECT_EQ(t.on_sequenced(7, 190), Arrival::kLate);
  EXPECT_EQ(t.counts().lost, 197);
}

TEST(SequenceTracker, ANewPublisherIsNeverLoss) {
  SequenceTracker t;
  for (uint64_t s = 1; s <= 10; ++s) t.on_sequenced(7, s);
  // Restarted: a new id, counting from 1 again.
  EXPECT_EQ(t.on_sequenced(8, 1), Arrival::kFirst);
  EXPECT_EQ(t.on_sequenced(8, 2), Arrival::kNext);
  // A receiver that started late hears a publisher at 5000 first.
  EXPECT_EQ(t.on_sequenced(9, 5000), Arrival::kFirst);
  EXPECT_EQ(t.counts().lost, 0);
  EXPECT_EQ(t.counts().duplicated, 0);
  EXPECT_EQ(t.counts().publishers, 3);
  // One overtaken before the first heard fills no gap: it was never lost.
  EXPECT_EQ(t.on_sequenced(9, 4999), Arrival::kDuplicate);
  EXPECT_EQ(t.counts().lost, 0);
}

TEST(SequenceTracker, PublishersAreCappedAndTheOneHeardLongestAgoGoes) {
  SequenceTracker t(3);
  t.on_sequenced(1, 1);
  t.on_sequenced(2, 1);
  t.on_sequenced(3, 1);
  t.on_sequenced(1, 2);  // 1 heard again: 2 is now the oldest
  EXPECT_EQ(t.on_sequenced(4, 1), Arrival::kFirst);
  EXPECT_EQ(t.publishers_held(), 3u);
  EXPECT_EQ(t.on_sequenced(1, 3), Arrival::kNext);   // still held
  EXPECT_EQ(t.on_sequenced(2, 5), Arrival::kFirst);  // evicted: new again, no loss
  EXPECT_EQ(t.counts().lost, 0);
  EXPECT_EQ(t.counts().publishers, 5);
  for (uint64_t id = 100; id < 1100; ++id) t.on_sequenced(id, 1);
  EXPECT_EQ(t.publishers_held(), 3u);
}

TEST(SequenceTracker, UnsequencedMessagesAreCountedAndTellNothing) {
  SequenceTracker t;
  EXPECT_EQ(t.on_unsequenced(), Arrival::kUnsequenced);
  t.on_sequenced(7, 1);
  EXPECT_EQ(t.on_unsequenced(), Arrival::kUnsequenced);
  t.on_sequenced(7, 2);
  EXPECT_EQ(t.counts().received, 4);
  EXPECT_EQ(t.counts().unsequenced, 2);
  EXPECT_EQ(t.counts().lost, 0);
}

TEST(SequenceTracker, AHugeJumpDoesNotWrapTheLostCount) {
  SequenceTracker t;
  t.on_sequenced(7, 1);
  t.on_sequenced(7, UINT64_MAX);
  EXPECT_EQ(t.counts().lost, INT64_MAX);
  t.on_sequenced(8, 1);
  t.on_sequenced(8, 3);
  EXPECT_EQ(t.counts().lost, INT64_MAX);
}

}  // namespace
}  // namespace ofn
