// The simulation master clock against a wall source the test moves.

#include <chrono>
#include <stdexcept>

#include <gtest/gtest.h>

#include "ofn/common/clock.hpp"

namespace ofn {
namespace {

using std::chrono::milliseconds;

std::chrono::steady_clock::time_point fake_wall;
std::chrono::steady_clock::time_point read_fake_wall() {
  return fake_wall;
}

class ScaledWallClockTest : public ::testing::Test {
 protected:
  void SetUp() override {
    fake_wall = std::chrono::steady_clock::time_point{} + std::chrono::hours(1);
  }
  // Reads the clock every `period` for `span` of wall time.
  static Utime run(const ScaledWallClock& clock, milliseconds span, milliseconds period) {
    Utime t = clock.now();
    for (auto done = milliseconds(0); done < span; done += period) {
      fake_wall += period;
      const Utime next = clock.now();
      EXPECT_GE(next, t);
      t = next;
    }
    return t;
  }
};

TEST_F(ScaledWallClockTest, RunsAtItsFactorWhileReadOften) {
  const ScaledWallClock clock(to_utime(10.0), 4.0, 0.5, &read_fake_wall);
  EXPECT_EQ(clock.now(), to_utime(10.0));
  EXPECT_EQ(run(clock, milliseconds(2000), milliseconds(10)), to_utime(10.0 + 8.0));
  EXPECT_EQ(clock.paused(), 0.0);
}

// Stopped for 3 s (SIGSTOP, a starved core): the simulated world waits. It
// advances by the allowance of 0.2 s of its own time (50 ms of wall at 4x),
// not by the 3 s (12 s at 4x).
TEST_F(ScaledWallClockTest, AStoppedSimulatorPausesTheWorld) {
  const ScaledWallClock clock(0, 4.0, 0.2, &read_fake_wall);
  run(clock, milliseconds(1000), milliseconds(10));
  EXPECT_EQ(clock.now(), to_utime(4.0));
  fake_wall += milliseconds(3000);
  EXPECT_EQ(clock.now(), to_utime(4.0 + 0.2));
  EXPECT_NEAR(clock.paused(), 2.95, 1e-9);
  // And runs on from there.
  EXPECT_EQ(run(clock, milliseconds(1000), milliseconds(10)), to_utime(4.2 + 4.0));
  // A gap within the allowance is time like any other.
  fake_wall += milliseconds(40);
  EXPECT_EQ(clock.now(), to_utime(8.2 + 0.16));
  EXPECT_NEAR(clock.paused(), 2.95, 1e-9);
}

// The whole host lost the CPU for 0.43 s at 2x real time: by default the
// airframe flies 0.05 s (five control periods) through it, not 0.86 s on
// the command it had.
TEST_F(ScaledWallClockTest, ByDefaultAHostStallIsNotFlownOpenLoop) {
  const ScaledWallClock clock(0, 2.0, ScaledWallClock::kDefaultMaxAdvance, &read_fake_wall);
  EXPECT_EQ(run(clock, milliseconds(500), milliseconds(5)), to_utime(1.0));
  fake_wall += milliseconds(430);
  EXPECT_EQ(clock.now(), to_utime(1.05));
}

TEST_F(ScaledWallClockTest, RefusesNonsense) {
  EXPECT_THROW(ScaledWallClock(0, 0.0), std::invalid_argument);
  EXPECT_THROW(ScaledWallClock(0, 1.0, 0.0), std::invalid_argument);
  EXPECT_THROW(ScaledWallClock(0, 1.0, -1.0), std::invalid_argument);
}

}  // namespace
}  // namespace ofn
