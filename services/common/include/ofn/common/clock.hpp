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

/// The system clock: field deployment.
class WallClock final : public Clock {
 public:
  Utime now() const override;
  std::string describe() const override { return "wall"; }
};

/// Simulation master clock: starts at `start` and advances at
/// `real_time_factor` times the wall (steady) clock. The simulated world
/// waits while its simulator does not run: wall time between two reads
/// beyond `stall` (a stopped or starved process; the simulator reads it at
/// its physics rate) does not advance the clock past `stall`. Jumping it
/// instead integrated seconds of the airframe at once on the last command
/// while every other service's SIM_CLOCK stood still.
class ScaledWallClock final : public Clock {
 public:
  using WallSource = std::chrono::steady_clock::time_point (*)();
  ScaledWallClock(Utime start, double real_time_factor, double stall = 0.5,
                  WallSource wall = &std::chrono::steady_clock::now);
  Utime now() const override;
  double wall_seconds_per_clock_second() const override { return 1.0 / factor_; }
  std::string describe() const override;
  /// Wall seconds the clock has waited out so far.
  double paused() const;

 private:
  Utime start_;
  double factor_;
  std::chrono::steady_clock::duration stall_;
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
  std::string describe() const override { return "lockstep"; }
  void set(Utime t) { now_ = t; }

 private:
  Utime now_;
};

}  // namespace ofn
