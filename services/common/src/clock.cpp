#include "ofn/common/clock.hpp"

#include <sstream>
#include <stdexcept>

namespace ofn {

Utime WallClock::now() const {
  return std::chrono::duration_cast<std::chrono::microseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

ScaledWallClock::ScaledWallClock(Utime start, double real_time_factor)
    : start_(start), factor_(real_time_factor), wall_start_(std::chrono::steady_clock::now()) {
  if (!(real_time_factor > 0.0)) throw std::invalid_argument("real-time factor must be > 0");
}

Utime ScaledWallClock::now() const {
  const double wall_elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start_).count();
  return start_ + to_utime(wall_elapsed * factor_);
}

std::string ScaledWallClock::describe() const {
  std::ostringstream s;
  s << "sim master (" << factor_ << "x real time)";
  return s.str();
}

}  // namespace ofn
