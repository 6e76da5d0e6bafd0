#pragma once
// Time as the flight code sees it: microsecond stamps and the clock
// interface every service reads time from (never the wall directly). The
// clocks themselves (wall, scaled, simulation-following, manual) are the
// runtime's: ofn/common/clock.hpp.

#include <cstdint>
#include <string>

namespace ofn {

/// Microseconds since the Unix epoch (wall) or since simulation start (sim).
using Utime = int64_t;

constexpr Utime kMicrosPerSecond = 1000000;
inline double to_seconds(Utime t) {
  return static_cast<double>(t) * 1e-6;
}
inline Utime to_utime(double seconds) {
  return static_cast<Utime>(seconds * 1e6 + (seconds >= 0 ? 0.5 : -0.5));
}

class Clock {
 public:
  virtual ~Clock() = default;
  /// Time of the clock: what messages are stamped with and judged by.
  virtual Utime now() const = 0;
  /// Time the timers run on. The same as now() but for the wall clock,
  /// whose now() steps with the system time (NTP, an operator setting the
  /// date): its timers run on the monotonic clock, so that a step neither
  /// fires a burst of callbacks nor silences them. Only differences of it
  /// mean anything.
  virtual Utime timer_now() const { return now(); }
  /// False until the clock has a time (a SIM_CLOCK-following clock before its
  /// first message).
  virtual bool valid() const { return true; }
  /// Wall seconds that pass per clock second; the process loop uses it to
  /// sleep until the next timer. Zero means "time only advances on messages".
  virtual double wall_seconds_per_clock_second() const { return 1.0; }
  /// True for a clock a program sets (the lockstep scheduler, tests), under
  /// which a run repeats to the bit: nothing random may then enter what is
  /// published (a Node's publisher id is derived from its name and this
  /// clock's time instead).
  virtual bool deterministic() const { return false; }
  virtual std::string describe() const = 0;
};

}  // namespace ofn
