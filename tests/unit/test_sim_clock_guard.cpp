#include <gtest/gtest.h>

#include "ofn/common/sim_clock_guard.hpp"

namespace ofn {
namespace {

using Verdict = SimClockGuard::Verdict;

// SIM_CLOCK at 100 Hz from `from` (s) for `seconds`; every verdict is `expected`.
void feed(SimClockGuard& guard, double from, double seconds, Verdict expected) {
  for (int i = 0; i < static_cast<int>(seconds * 100.0); ++i)
    ASSERT_EQ(guard.offer(to_utime(from + 0.01 * i)), expected) << "at " << from + 0.01 * i;
}

TEST(SimClockGuard, FollowsASteadyClockAndSmallGaps) {
  SimClockGuard guard;
  feed(guard, 5.0, 3.0, Verdict::kAccepted);
  // A lost second of messages is still the same timeline.
  EXPECT_EQ(guard.offer(to_utime(8.99)), Verdict::kAccepted);
  // A duplicate is harmless.
  EXPECT_EQ(guard.offer(to_utime(8.99)), Verdict::kAccepted);
  EXPECT_EQ(guard.followed(), to_utime(8.99));
}

TEST(SimClockGuard, OneStampFarAheadIsRefusedAndTheClockGoesOn) {
  SimClockGuard guard;
  feed(guard, 0.0, 2.0, Verdict::kAccepted);
  EXPECT_EQ(guard.offer(to_utime(1001.99)), Verdict::kRejected);
  EXPECT_EQ(guard.reason(), "jumps ahead by 1000.000 s");
  EXPECT_EQ(guard.followed(), to_utime(1.99));
  feed(guard, 2.0, 1.0, Verdict::kAccepted);
}

TEST(SimClockGuard, AStampBehindIsRefused) {
  SimClockGuard guard;
  feed(guard, 10.0, 1.0, Verdict::kAccepted);
  EXPECT_EQ(guard.offer(to_utime(10.5)), Verdict::kRejected);
  EXPECT_EQ(guard.reason(), "goes back by 0.490 s");
  EXPECT_EQ(guard.offer(to_utime(11.0)), Verdict::kAccepted);
}

TEST(SimClockGuard, AForgedStreamBesideTheRealOneIsNeverFollowed) {
  // A stranger publishing its own timeline as fast as the real one, for
  // longer than the resync time: each real stamp restarts its wait.
  SimClockGuard guard;
  guard.offer(0);
  for (int i = 1; i < 1000; ++i) {
    ASSERT_EQ(guard.offer(to_utime(0.01 * i)), Verdict::kAccepted);
    ASSERT_EQ(guard.offer(to_utime(500.0 + 0.01 * i)), Verdict::kRejected);
  }
  EXPECT_EQ(guard.followed(), to_utime(9.99));
}

TEST(SimClockGuard, ARestartedSimulationIsFollowedAfterItKeepsItsTime) {
  SimClockGuard guard;
  feed(guard, 0.0, 30.0, Verdict::kAccepted);
  // The master restarts at zero and the old one is gone: refused for two
  // seconds of the new time, then followed.
  feed(guard, 0.0, 2.0, Verdict::kRejected);
  EXPECT_EQ(guard.offer(to_utime(2.0)), Verdict::kResynced);
  EXPECT_EQ(guard.followed(), to_utime(2.0));
  EXPECT_EQ(guard.offer(to_utime(2.01)), Verdict::kAccepted);
}

TEST(SimClockGuard, TheFirstStampIsTakenWhateverItIs) {
  SimClockGuard guard;
  EXPECT_EQ(guard.followed(), INT64_MIN);
  EXPECT_EQ(guard.offer(to_utime(12345.0)), Verdict::kAccepted);
}

TEST(SimClockGuard, BadLimitsAreRefused) {
  EXPECT_THROW(SimClockGuard(SimClockGuardLimits{0.0, 2.0}), std::invalid_argument);
  EXPECT_THROW(SimClockGuard(SimClockGuardLimits{1.0, -1.0}), std::invalid_argument);
}

}  // namespace
}  // namespace ofn
