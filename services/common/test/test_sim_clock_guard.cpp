#include <gtest/gtest.h>

#include "ofn/common/sim_clock_guard.hpp"

namespace ofn {
namespace {

using Verdict = SimClockGuard::Verdict;

// Arrival times: a wall clock that runs on from the first message, as fast
// as the simulation (real time).
struct Arrivals {
  Utime now = to_utime(5000.0);
  Utime next(double seconds) { return now += to_utime(seconds); }
};

// SIM_CLOCK at 100 Hz from `from` (s) for `seconds`, arriving 10 ms apart;
// every verdict is `expected`.
void feed(SimClockGuard& guard, Arrivals& wall, double from, double seconds, Verdict expected) {
  for (int i = 0; i < static_cast<int>(seconds * 100.0); ++i)
    ASSERT_EQ(guard.offer(to_utime(from + 0.01 * i), wall.next(0.01)), expected)
        << "at " << from + 0.01 * i;
}

TEST(SimClockGuard, FollowsASteadyClockAndSmallGaps) {
  SimClockGuard guard;
  Arrivals wall;
  feed(guard, wall, 5.0, 3.0, Verdict::kAccepted);
  // A lost second of messages is still the same timeline.
  EXPECT_EQ(guard.offer(to_utime(8.99), wall.next(1.0)), Verdict::kAccepted);
  // A duplicate is harmless.
  EXPECT_EQ(guard.offer(to_utime(8.99), wall.next(0.0)), Verdict::kAccepted);
  EXPECT_EQ(guard.followed(), to_utime(8.99));
}

TEST(SimClockGuard, OneStampFarAheadIsRefusedAndTheClockGoesOn) {
  SimClockGuard guard;
  Arrivals wall;
  feed(guard, wall, 0.0, 2.0, Verdict::kAccepted);
  EXPECT_EQ(guard.offer(to_utime(1001.99), wall.next(0.001)), Verdict::kRejected);
  EXPECT_EQ(guard.reason(), "jumps ahead by 1000.000 s");
  EXPECT_EQ(guard.followed(), to_utime(1.99));
  feed(guard, wall, 2.0, 1.0, Verdict::kAccepted);
}

TEST(SimClockGuard, AStampBehindIsRefused) {
  SimClockGuard guard;
  Arrivals wall;
  feed(guard, wall, 10.0, 1.0, Verdict::kAccepted);
  EXPECT_EQ(guard.offer(to_utime(10.5), wall.next(0.001)), Verdict::kRejected);
  EXPECT_EQ(guard.reason(), "goes back by 0.490 s");
  EXPECT_EQ(guard.offer(to_utime(11.0), wall.next(0.01)), Verdict::kAccepted);
}

TEST(SimClockGuard, AForgedStreamBesideTheRealOneIsNeverFollowed) {
  // A stranger publishing its own timeline as fast as the real one, for
  // longer than the resync time: each real stamp restarts its wait.
  SimClockGuard guard;
  Arrivals wall;
  guard.offer(0, wall.next(0.0));
  for (int i = 1; i < 1000; ++i) {
    ASSERT_EQ(guard.offer(to_utime(0.01 * i), wall.next(0.005)), Verdict::kAccepted);
    ASSERT_EQ(guard.offer(to_utime(500.0 + 0.01 * i), wall.next(0.005)), Verdict::kRejected);
  }
  EXPECT_EQ(guard.followed(), to_utime(9.99));
}

TEST(SimClockGuard, ABurstOfForgedStampsSpanningTheResyncTimeIsNeverFollowed) {
  // Stamps 500, 501, 502, ... s sent back to back between two real ticks
  // span the resync time in their own time, not in arrival time.
  SimClockGuard guard;
  Arrivals wall;
  feed(guard, wall, 0.0, 1.0, Verdict::kAccepted);
  for (int burst = 0; burst < 20; ++burst) {
    for (int k = 0; k < 5; ++k)
      ASSERT_EQ(guard.offer(to_utime(500.0 + burst * 10.0 + k), wall.next(0.0001)),
                Verdict::kRejected);
    feed(guard, wall, 1.0 + 0.1 * burst, 0.1, Verdict::kAccepted);
  }
}

TEST(SimClockGuard, ARestartedSimulationIsFollowedAfterItKeepsItsTime) {
  SimClockGuard guard;
  Arrivals wall;
  feed(guard, wall, 0.0, 30.0, Verdict::kAccepted);
  // The master restarts at zero and the old one is gone: refused for two
  // seconds of the new time, then followed.
  feed(guard, wall, 0.0, 2.0, Verdict::kRejected);
  EXPECT_EQ(guard.offer(to_utime(2.0), wall.next(0.01)), Verdict::kResynced);
  EXPECT_EQ(guard.followed(), to_utime(2.0));
  EXPECT_EQ(guard.offer(to_utime(2.01), wall.next(0.01)), Verdict::kAccepted);
}

TEST(SimClockGuard, ARestartedFastSimulationWaitsForTheWallTimeToo) {
  // At ten times real time two seconds of the new timeline arrive in 0.2 s
  // of wall time: followed only after a second of wall time.
  SimClockGuard guard;
  Arrivals wall;
  feed(guard, wall, 0.0, 30.0, Verdict::kAccepted);
  int rejected = 0;
  Verdict last = Verdict::kRejected;
  for (int i = 0; last == Verdict::kRejected && i < 10000; ++i) {
    last = guard.offer(to_utime(0.01 * i), wall.next(0.001));
    rejected += last == Verdict::kRejected;
  }
  EXPECT_EQ(last, Verdict::kResynced);
  EXPECT_EQ(rejected, 1000);
}

// SIM_CLOCK at 100 Hz of simulated time, `rtf` times real time.
void feed_at(SimClockGuard& guard, Arrivals& wall, double from, double seconds, double rtf) {
  for (int i = 0; i < static_cast<int>(seconds * 100.0); ++i)
    ASSERT_EQ(guard.offer(to_utime(from + 0.01 * i), wall.next(0.01 / rtf)), Verdict::kAccepted)
        << "at " << from + 0.01 * i;
}

TEST(SimClockGuard, AProcessStoppedForSecondsFollowsTheTimeThatRanOnAtOnce) {
  // SIGSTOP for 3 s: nothing is read, then the stamp 3 s on. Waiting for the
  // resync froze the service 2 s more and the hang watch restarted it.
  SimClockGuard guard;
  Arrivals wall;
  feed_at(guard, wall, 0.0, 5.0, 1.0);
  EXPECT_NEAR(guard.rate(), 1.0, 0.01);
  EXPECT_EQ(guard.offer(to_utime(7.99), wall.next(3.0)), Verdict::kCaughtUp);
  EXPECT_EQ(guard.reason(), "jumps ahead by 3.000 s after a silence of 3.000 s");
  EXPECT_EQ(guard.followed(), to_utime(7.99));
  feed_at(guard, wall, 8.0, 1.0, 1.0);
}

TEST(SimClockGuard, StampsQueuedDuringTheStopComeFirst) {
  // An open bus keeps what arrived while the process was stopped: the
  // queued stamps are read at once, then the live one, 3 s on.
  SimClockGuard guard;
  Arrivals wall;
  feed_at(guard, wall, 0.0, 5.0, 1.0);
  EXPECT_EQ(guard.offer(to_utime(5.0), wall.next(3.0)), Verdict::kAccepted);
  for (int i = 1; i < 30; ++i)
    ASSERT_EQ(guard.offer(to_utime(5.0 + 0.01 * i), wall.next(0.00001)), Verdict::kAccepted);
  EXPECT_EQ(guard.offer(to_utime(8.0), wall.next(0.00001)), Verdict::kCaughtUp);
  feed_at(guard, wall, 8.01, 1.0, 1.0);
}

TEST(SimClockGuard, ASilenceAllowsOnlyWhatTheSimulationCouldHaveRun) {
  // At 4x real time a 3 s silence may hold 12 s of simulated time (and the
  // margin), not 20 s, and never 1,000 s.
  SimClockGuard guard;
  Arrivals wall;
  feed_at(guard, wall, 0.0, 8.0, 4.0);
  EXPECT_NEAR(guard.rate(), 4.0, 0.05);
  EXPECT_EQ(guard.offer(to_utime(1000.0), wall.next(3.0)), Verdict::kRejected);
  EXPECT_EQ(guard.offer(to_utime(28.0), wall.next(0.001)), Verdict::kRejected);
  EXPECT_EQ(guard.offer(to_utime(19.99), wall.next(0.001)), Verdict::kCaughtUp);
}

TEST(SimClockGuard, WithoutASilenceAStepOfSecondsIsStillRefused) {
  SimClockGuard guard;
  Arrivals wall;
  feed_at(guard, wall, 0.0, 5.0, 1.0);
  EXPECT_EQ(guard.offer(to_utime(7.99), wall.next(0.01)), Verdict::kRejected);
  // Nor a second after a silence ended.
  EXPECT_EQ(guard.offer(to_utime(5.0), wall.next(0.6)), Verdict::kAccepted);
  feed_at(guard, wall, 5.01, 1.5, 1.0);
  EXPECT_EQ(guard.offer(to_utime(9.0), wall.next(0.01)), Verdict::kRejected);
}

TEST(SimClockGuard, NoRateNoCatchUp) {
  // Before a rate is measured (under 0.5 s of stamps) a silence proves
  // nothing: the old rule, resync after keeping the new time.
  SimClockGuard guard;
  Arrivals wall;
  feed_at(guard, wall, 0.0, 0.3, 1.0);
  EXPECT_EQ(guard.rate(), 0.0);
  EXPECT_EQ(guard.offer(to_utime(3.3), wall.next(3.0)), Verdict::kRejected);
}

TEST(SimClockGuard, TheFirstStampIsTakenWhateverItIs) {
  SimClockGuard guard;
  EXPECT_EQ(guard.followed(), INT64_MIN);
  EXPECT_EQ(guard.offer(to_utime(12345.0), 0), Verdict::kAccepted);
}

TEST(SimClockGuard, BadLimitsAreRefused) {
  EXPECT_THROW(SimClockGuard(SimClockGuardLimits{0.0, 2.0, 1.0}), std::invalid_argument);
  EXPECT_THROW(SimClockGuard(SimClockGuardLimits{1.0, -1.0, 1.0}), std::invalid_argument);
  EXPECT_THROW(SimClockGuard(SimClockGuardLimits{1.0, 2.0, -1.0}), std::invalid_argument);
  EXPECT_THROW(SimClockGuard(SimClockGuardLimits{1.0, 2.0, 1.0, 0.0, 1.25}), std::invalid_argument);
  EXPECT_THROW(SimClockGuard(SimClockGuardLimits{1.0, 2.0, 1.0, 0.5, 0.9}), std::invalid_argument);
}

}  // namespace
}  // namespace ofn
