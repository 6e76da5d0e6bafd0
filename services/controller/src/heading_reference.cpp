#include "ofn/controller/heading_reference.hpp"

#include <algorithm>
#include <cmath>

namespace ofn::control {

void PathHeadingFilter::reset(double yaw) {
  yaw_ = yaw;
  initialised_ = true;
}

double PathHeadingFilter::update(const std::optional<Vec3>& facing, double dt) {
  if (facing) {
    const double step = wrap_angle(std::atan2(facing->y(), facing->x()) - yaw_);
    const double limit = settings_.max_rate * dt;
    yaw_ = wrap_angle(yaw_ + std::clamp(step, -limit, limit));
  }
  return yaw_;
}

std::optional<Vec3> facing_along(const Vec3& direction, double min_horizontal) {
  if (std::hypot(direction.x(), direction.y()) > min_horizontal) return direction;
  return std::nullopt;
}

std::optional<Vec3> facing_ahead(const Vec3& here, const Vec3& velocity,
                                 const std::optional<Vec3>& ahead, double min_speed) {
  if (std::hypot(velocity.x(), velocity.y()) <= min_speed) return std::nullopt;
  if (ahead) {
    const Vec3 d = *ahead - here;
    // Ahead by less than a metre (a plan about to end) points nowhere useful.
    if (std::hypot(d.x(), d.y()) > 1.0) return d;
  }
  return velocity;
}

Vec3 look_around_facing(double yaw) {
  const double ahead = yaw + 0.5 * kPi;
  return Vec3(std::cos(ahead), std::sin(ahead), 0.0);
}

double yaw_sweep_offset(const YawSweep& sweep, double t, double* rate) {
  const double w = 2.0 * kPi * sweep.frequency;
  const double ramp = 1.0 / sweep.frequency;
  const double half = 0.5 * sweep.total_angle;
  const double a = half * std::min(1.0, t / ramp);
  const double a_rate = t < ramp ? half / ramp : 0.0;
  *rate = a_rate * std::sin(w * t) + a * w * std::cos(w * t);
  return a * std::sin(w * t);
}

}  // namespace ofn::control
