#pragma once
// Clock objects: every service reads time from one of these, never from the
// wall directly, so the same code runs in the field, in a real-time
// simulation and in the deterministic lockstep runner.

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>

#include "ofn/common/time.hpp"

namespace ofn {

/// The system clock: field deployment. Messages are stamped with the
/// system time (microseconds since the epoch), which NTP or an operator may
/// step; timers run on the monotonic clock, which never steps.
class WallClock final : public Clock {
 public:
  using SystemSource = std::chrono::system_clock::time_point (*)();
  using SteadySource = std::chrono::steady_clock::time_point (*)();
  explicit WallClock(SystemSource system = &std::chrono::system_clock::now,
                     SteadySource steady = &std::chrono::steady_clock::now)
      : system_(system), steady_(steady) {}
  Utime now() const override;
  Utime timer_now() const override;
  std::string describe() const override { return "wall"; }

 private:
  SystemSource system_;
  SteadySource steady_;
};

/// Simulation master clock: starts at `start` and advances at
/// `real_time_factor` times the wall (steady) clock. The simulated world
/// waits while its simulator does not run: between two reads (the
/// simulator reads it at its physics rate) the clock advances by at most
/// `max_advance` seconds of its own time, whatever the wall did (a stopped
/// or starved process, a host that lost the CPU). Jumping it instead
/// integrated the airframe open loop on the last command through the gap
/// while every other service's SIM_CLOCK stood still: a 0.43 s stall of
/// the whole host at 2x real time flew 0.87 s without control, and the
/// controller found its reference lapsed. The default, 0.05 s, is five
/// periods of the 100 Hz control loop.
class ScaledWallClock final : public Clock {
 public:
  using WallSource = std::chrono::steady_clock::time_point (*)();
  static constexpr double kDefaultMaxAdvance = 0.05;  // s of simulated time
  ScaledWallClock(Utime start, double real_time_factor, double max_advance = kDefaultMaxAdvance,
                  WallSource wall = &std::chrono::steady_clock::now);
  Utime now() const override;
  double wall_seconds_per_clock_second() const override { return 1.0 / factor_; }
  std::string describe() const override;
  /// Wall seconds the clock has waited out so far.
  double paused() const;

 private:
  Utime start_;
  double factor_;
  std::chrono::steady_clock::duration stall_;  // wall time of max_advance
  WallSource wall_;
  std::chrono::steady_clock::time_point wall_start_;
  mutable std::mutex mutex_;
  mutable std::chrono::steady_clock::time_point last_read_;
  mutable std::chrono::steady_clock::duration paused_{0};
};

/// Follows the SIM_CLOCK messages of the simulation master.
class SimFollowClock final : public Clock {
 public:
  Utime now() const override { return now_.load(); }
  bool valid() const override { return valid_.load(); }
  double wall_seconds_per_clock_second() const override { return 0.0; }
  std::string describe() const override { return "sim (follows SIM_CLOCK)"; }
  void update(Utime t) {
    now_.store(t);
    valid_.store(true);
  }

 private:
  std::atomic<Utime> now_{0};
  std::atomic<bool> valid_{false};
};

/// Set explicitly by the lockstep scheduler; deterministic.
class ManualClock final : public Clock {
 public:
  explicit ManualClock(Utime start = 0) : now_(start) {}
  Utime now() const override { return now_; }
  double wall_seconds_per_clock_second() const override { return 0.0; }
  bool deterministic() const override { return true; }
  std::string describe() const override { return "lockstep"; }
  void set(Utime t) { now_ = t; }

 private:
  Utime now_;
};

}  // namespace ofn
