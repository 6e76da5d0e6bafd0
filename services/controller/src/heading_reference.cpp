#include "ofn/controller/heading_reference.hpp"

#include <algorithm>
#include <cmath>

#include "ofn/common/braking.hpp"

namespace ofn::control {

void PathHeadingFilter::reset(double yaw) {
  yaw_ = yaw;
  turn_rate_ = 0;
  initialised_ = true;
}

double PathHeadingFilter::update(const std::optional<Vec3>& facing, double dt) {
  if (!(dt > 0)) return yaw_;
  const double accel = std::max(settings_.max_accel, 1e-6);
  const double step = accel * dt;
  // The rate wanted now: toward the direction, no faster than a turn that
  // starts braking at max_accel from the next step can still stop on it
  // (r dt + r^2 / 2a = |error|); none without a direction.
  double wanted = 0;
  if (facing) {
    const double error = wrap_angle(std::atan2(facing->y(), facing->x()) - yaw_);
    // The last step of a turn lands on the direction.
    if (std::abs(error) <= step * dt && std::abs(turn_rate_) <= step) {
      yaw_ = wrap_angle(yaw_ + error);
      turn_rate_ = error / dt;
      return yaw_;
    }
    const double stoppable = std::sqrt(step * step + 2.0 * accel * std::abs(error)) - step;
    wanted = std::copysign(std::min(settings_.max_rate, stoppable), error);
  }
  turn_rate_ = std::clamp(wanted, turn_rate_ - step, turn_rate_ + step);
  yaw_ = wrap_angle(yaw_ + turn_rate_ * dt);
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

Vec3 look_around_facing(double yaw, bool left) {
  const double ahead = yaw + (left ? -0.5 : 0.5) * kPi;
  return Vec3(std::cos(ahead), std::sin(ahead), 0.0);
}

namespace {

/// The sweep's half angles (rad): at cruise, and at the widest.
double nominal_half_angle(const YawSweep& sweep) {
  return 0.5 * sweep.total_angle;
}
double widest_half_angle(const YawSweep& sweep) {
  return std::max(nominal_half_angle(sweep), 0.5 * sweep.wide_total_angle);
}

}  // namespace

double sweep_half_angle(const YawSweep& sweep, double speed, double slow_speed,
                        const SweepCoverage& coverage) {
  if (std::isfinite(speed) && speed < slow_speed) return widest_half_angle(sweep);
  const double nominal = nominal_half_angle(sweep);
  if (!sweep.cover_clearance || !std::isfinite(speed) || !(coverage.clearance > 0) ||
      !std::isfinite(coverage.clearance) || !(coverage.deceleration > 0) ||
      !std::isfinite(coverage.deceleration))
    return nominal;
  // The stop without its onset: the shorter distance asks for the wider
  // sweep. Taken with the onset (0.9 m longer at cruise) the sweep narrowed
  // from +-27 to +-25 deg, and dense field 15 passed a cylinder beside a
  // turning path that no beam had hit at 0.72 R_s again.
  const double stopping =
      stop_from(Vec3::Zero(), Vec3(speed, 0.0, 0.0), coverage.deceleration, kStopRampTime, 0.0)
          .distance();
  const double widest = std::min(widest_half_angle(sweep), 0.5 * sweep.cover_total_angle);
  return std::clamp(std::atan2(coverage.clearance, stopping), nominal, std::max(nominal, widest));
}

void YawSweepGenerator::restart() {
  half_ = 0;
  half_rate_ = 0;
  phase_ = 0;
  faded_in_ = false;
}

double YawSweepGenerator::update(double target_half_angle, double dt, double* rate) {
  const double nominal = nominal_half_angle(sweep_);
  const double wide = widest_half_angle(sweep_);
  const double target = std::clamp(target_half_angle, nominal, wide);
  // How the half angle moves over the coming step.
  bool fade_ends = false;
  if (!faded_in_) {
    // A linear fade over one period: it ends at a whole turn of the phase,
    // where sin = 0, so the rate does not step when the fade stops.
    half_rate_ = nominal * sweep_.frequency;
    if (half_ + half_rate_ * dt >= nominal) {
      half_rate_ = dt > 0 ? (nominal - half_) / dt : 0.0;
      faded_in_ = fade_ends = true;
    }
  } else {
    // Toward the target within kWidenSettle, at most widen_rate, the rate
    // itself changing at most widen_rate per kWidenSettle: the yaw rate
    // never steps.
    const double desired =
        std::clamp((target - half_) / kWidenSettle, -sweep_.widen_rate, sweep_.widen_rate);
    const double change = sweep_.widen_rate * dt / kWidenSettle;
    half_rate_ += std::clamp(desired - half_rate_, -change, change);
    if (half_ + half_rate_ * dt < nominal || half_ + half_rate_ * dt > wide)
      half_rate_ = dt > 0 ? (std::clamp(half_ + half_rate_ * dt, nominal, wide) - half_) / dt : 0.0;
  }
  // This step's offset and rate, from the state reached so far (the first
  // step of a sweep commands zero), then the state moves on.
  const double w = 2.0 * kPi * sweep_.frequency * (half_ > nominal ? nominal / half_ : 1.0);
  const double offset = half_ * std::sin(phase_);
  *rate = half_rate_ * std::sin(phase_) + half_ * w * std::cos(phase_);
  half_ += half_rate_ * dt;
  phase_ = std::fmod(phase_ + w * dt, 2.0 * kPi);
  if (fade_ends) half_rate_ = 0;
  return offset;
}

}  // namespace ofn::control
