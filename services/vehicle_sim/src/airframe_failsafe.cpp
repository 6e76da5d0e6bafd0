#include "ofn/vehicle_sim/airframe_failsafe.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace ofn::vehicle {

HoverStabiliser::HoverStabiliser(const RotorcraftParams& airframe, StabiliserGains gains)
    : airframe_(airframe), gains_(gains) {
  const RotorcraftModel model(airframe_);
  const TrimResult t = trim(model, Vec3::Zero(), 0.0);
  if (!t.converged)
    throw std::invalid_argument("the airframe's stabiliser: no hover trim for this airframe");
  hover_ = t.controls;
  const Vec3 euler = euler_from_quat(t.state.attitude);
  hover_roll_ = euler.x();
  hover_pitch_ = euler.y();
}

void HoverStabiliser::engage(const RotorcraftState& s) {
  hold_heading_ = euler_from_quat(s.attitude).z();
  hold_down_ = s.position.z();
}

Controls HoverStabiliser::command(const RotorcraftState& s) const {
  const StabiliserGains& k = gains_;
  const Vec3 euler = euler_from_quat(s.attitude);
  const double roll = euler.x(), pitch = euler.y(), yaw = euler.z();
  // Velocity damping: the horizontal acceleration asked, in heading axes.
  const double c = std::cos(yaw), sn = std::sin(yaw);
  const double forward = c * s.velocity.x() + sn * s.velocity.y();
  const double right = -sn * s.velocity.x() + c * s.velocity.y();
  double accel_forward = -k.velocity_damping * forward;
  double accel_right = -k.velocity_damping * right;
  const double max_accel = kGravity * std::tan(k.max_tilt);
  const double asked = std::hypot(accel_forward, accel_right);
  if (asked > max_accel) {
    accel_forward *= max_accel / asked;
    accel_right *= max_accel / asked;
  }
  // Attitude hold about the hover's, tilted by what the damping asks
  // (nose down accelerates forward, right wing down to the right).
  const double pitch_wanted = hover_pitch_ + std::atan(-accel_forward / kGravity);
  const double roll_wanted = hover_roll_ + std::atan(accel_right / kGravity);
  const Vec3& rates = s.body_rates;
  Controls out;
  out.lon_cyclic =
      hover_.lon_cyclic - k.attitude_gain * (pitch_wanted - pitch) + k.rate_gain * rates.y();
  out.lat_cyclic =
      hover_.lat_cyclic + k.attitude_gain * (roll_wanted - roll) - k.rate_gain * rates.x();
  out.pedal =
      hover_.pedal + k.heading_gain * wrap_angle(hold_heading_ - yaw) - k.yaw_rate_gain * rates.z();
  out.collective = hover_.collective + k.climb_damping * s.velocity.z() +
                   k.height_gain * (s.position.z() - hold_down_);
  return clamp_controls(out, airframe_);
}

AirframeFailsafe::AirframeFailsafe(const RotorcraftParams& airframe, double command_timeout,
                                   StabiliserGains gains)
    : stabiliser_(airframe, gains), timeout_(command_timeout) {
  if (!std::isfinite(command_timeout) || command_timeout < 0)
    throw std::invalid_argument("command_timeout: expected 0 (off) or a time > 0 s, not " +
                                std::to_string(command_timeout));
}

bool AirframeFailsafe::command_received(double t) {
  last_command_ = last_command_ ? std::max(*last_command_, t) : t;
  const bool handed_back = engaged_;
  engaged_ = false;
  return handed_back;
}

std::optional<Controls> AirframeFailsafe::update(double t, const RotorcraftState& s) {
  if (!engaged_ && enabled() && armed() && t - *last_command_ > timeout_) {
    engaged_ = true;
    engaged_since_ = t;
    ++takeovers_;
    stabiliser_.engage(s);
  }
  if (!engaged_) return std::nullopt;
  return stabiliser_.command(s);
}

}  // namespace ofn::vehicle
