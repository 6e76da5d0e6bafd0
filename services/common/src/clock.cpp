#include "ofn/common/clock.hpp"

#include <algorithm>
#include <sstream>
#include <stdexcept>

namespace ofn {

Utime WallClock::now() const {
  return std::chrono::duration_cast<std::chrono::microseconds>(system_().time_since_epoch())
      .count();
}

Utime WallClock::timer_now() const {
  return std::chrono::duration_cast<std::chrono::microseconds>(steady_().time_since_epoch())
      .count();
}

ScaledWallClock::ScaledWallClock(Utime start, double real_time_factor, double max_advance,
                                 WallSource wall)
    : start_(start),
      factor_(real_time_factor),
      wall_(wall),
      wall_start_(wall()),
      last_read_(wall_start_) {
  if (!(real_time_factor > 0.0)) throw std::invalid_argument("real-time factor must be > 0");
  if (!(max_advance > 0.0)) throw std::invalid_argument("max_advance must be > 0");
  // After the checks: the allowance in wall time divides by the factor.
  stall_ = std::chrono::duration_cast<std::chrono::steady_clock::duration>(
      std::chrono::duration<double>(max_advance / real_time_factor));
}

Utime ScaledWallClock::now() const {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto wall = wall_();
  if (wall - last_read_ > stall_) paused_ += wall - last_read_ - stall_;
  last_read_ = std::max(last_read_, wall);
  const double wall_elapsed =
      std::chrono::duration<double>(last_read_ - wall_start_ - paused_).count();
  return start_ + to_utime(wall_elapsed * factor_);
}

double ScaledWallClock::paused() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return std::chrono::duration<double>(paused_).count();
}

std::string ScaledWallClock::describe() const {
  std::ostringstream s;
  s << "sim master (" << factor_ << "x real time)";
  return s.str();
}

}  // namespace ofn
