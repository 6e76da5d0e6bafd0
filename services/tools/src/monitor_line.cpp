#include "ofn/tools/monitor_line.hpp"

#include <cstdio>

namespace ofn::report {

std::string progress_line(double t, const Vec3& position, const Vec3& velocity,
                          const std::string& mode, const DisplayUnit& unit) {
  const double k = 1.0 / unit.metres_per_unit;
  const char* u = unit.name.c_str();
  char line[256];
  std::snprintf(line, sizeof line,
                "t=%6.1f s  north %8.1f %s  east %6.1f %s  alt %6.1f %s  speed %5.2f %s/s  mode %s",
                t, position.x() * k, u, position.y() * k, u, -position.z() * k, u,
                velocity.norm() * k, u, mode.c_str());
  return line;
}

}  // namespace ofn::report
