// WallClock: messages stamped with the system time, timers run on the
// monotonic clock, so a step of the system time (NTP, an operator setting
// the date) neither bursts nor silences a node's timers. Fake sources for
// both clocks, a node on memq://.

#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "ofn/common/clock.hpp"
#include "ofn/common/node.hpp"
#include "ofn/common/validate/heartbeat.hpp"
#include "ofn/heartbeat_t.hpp"

namespace ofn {
namespace {

using std::chrono::microseconds;

// The fake system and monotonic times, us.
Utime g_system_us = 0;
Utime g_steady_us = 0;

std::chrono::system_clock::time_point fake_system() {
  return std::chrono::system_clock::time_point(
      std::chrono::duration_cast<std::chrono::system_clock::duration>(microseconds(g_system_us)));
}
std::chrono::steady_clock::time_point fake_steady() {
  return std::chrono::steady_clock::time_point(
      std::chrono::duration_cast<std::chrono::steady_clock::duration>(microseconds(g_steady_us)));
}

constexpr Utime kEpoch = 1'790'000'000 * kMicrosPerSecond;  // 2026
constexpr Utime kStep = 1000 * kMicrosPerSecond;
constexpr Utime kTick = 10000;  // the process loop's pace in this test, us

// One timer callback.
struct Firing {
  Utime steady;  // monotonic time of the call
  Utime stamp;   // what the clock stamps with then
  int calls;     // callbacks in that fire_due_timers call
};

class WallClockTimers : public ::testing::Test {
 protected:
  WallClockTimers() : lcm_("memq://"), clock_(&fake_system, &fake_steady) {
    g_system_us = kEpoch;
    g_steady_us = 5000 * kMicrosPerSecond;
  }

  void deliver() {
    while (lcm_.handleTimeout(0) > 0) {
    }
  }

  /// Runs a node with a 0.1 s timer for 2 s of monotonic time, the system
  /// time stepping by `step` after 1 s; returns each callback.
  std::vector<Firing> fly(Utime step, std::vector<heartbeat_t>* beats = nullptr) {
    Node node("wall", lcm_, clock_);
    Node monitor("monitor", lcm_, clock_);
    if (beats)
      monitor.subscribe<heartbeat_t>(heartbeat_channel("wall"),
                                     [beats](const heartbeat_t& h) { beats->push_back(h); });
    std::vector<Firing> fired;
    int calls = 0;
    node.add_timer(
        0.1,
        [&] {
          ++calls;
          fired.push_back({g_steady_us, clock_.now(), 0});
        },
        "100ms");
    for (Utime t = 0; t <= 2 * kMicrosPerSecond; t += kTick) {
      if (t == kMicrosPerSecond + 5 * kTick) g_system_us += step;
      calls = 0;
      node.fire_due_timers();
      if (calls > 0) fired.back().calls = calls;
      deliver();
      g_system_us += kTick;
      g_steady_us += kTick;
    }
    return fired;
  }

  lcm::LCM lcm_;
  WallClock clock_;
};

void expect_on_period(const std::vector<Firing>& fired) {
  // 2 s at 0.1 s: 21 callbacks (at 0 and 2 s both), one per call, 0.1 s of
  // monotonic time apart across the step.
  ASSERT_EQ(fired.size(), 21u);
  for (size_t i = 0; i < fired.size(); ++i) {
    EXPECT_EQ(fired[i].calls, 1) << i;
    if (i > 0) {
      EXPECT_EQ(fired[i].steady - fired[i - 1].steady, 100000) << i;
    }
  }
}

TEST_F(WallClockTimers, StampsAreSystemTimeAndTimersMonotonicTime) {
  EXPECT_EQ(clock_.now(), kEpoch);
  EXPECT_EQ(clock_.timer_now(), 5000 * kMicrosPerSecond);
  g_system_us += kStep;
  EXPECT_EQ(clock_.now(), kEpoch + kStep);
  EXPECT_EQ(clock_.timer_now(), 5000 * kMicrosPerSecond);
}

TEST_F(WallClockTimers, ASystemTimeStepForwardNeitherBurstsNorSilences) {
  std::vector<heartbeat_t> beats;
  const auto fired = fly(kStep, &beats);
  expect_on_period(fired);
  // The stamps follow the system time: 1,000 s on after the step.
  EXPECT_EQ(fired[10].stamp, kEpoch + kMicrosPerSecond);
  EXPECT_EQ(fired[11].stamp, kEpoch + kStep + 11 * 100000);
  // So do the heartbeats' stamps; their uptime is monotonic.
  ASSERT_EQ(beats.size(), 3u);
  EXPECT_EQ(beats[1].utime, kEpoch + kMicrosPerSecond);
  EXPECT_EQ(beats[2].utime, kEpoch + kStep + 2 * kMicrosPerSecond);
  EXPECT_NEAR(beats[2].uptime, 2.0, 1e-9);
}

TEST_F(WallClockTimers, ASystemTimeStepBackNeitherBurstsNorSilences) {
  const auto fired = fly(-kStep);
  expect_on_period(fired);
  EXPECT_EQ(fired[11].stamp, kEpoch - kStep + 11 * 100000);
}

TEST(WallClock, ReadsTheSystemClockByDefault) {
  const WallClock clock;
  const Utime system =
      std::chrono::duration_cast<microseconds>(std::chrono::system_clock::now().time_since_epoch())
          .count();
  const Utime steady =
      std::chrono::duration_cast<microseconds>(std::chrono::steady_clock::now().time_since_epoch())
          .count();
  // Within a minute of what this test read; the two are different clocks.
  EXPECT_LT(std::abs(clock.now() - system), 60 * kMicrosPerSecond);
  EXPECT_LT(std::abs(clock.timer_now() - steady), 60 * kMicrosPerSecond);
}

}  // namespace
}  // namespace ofn
