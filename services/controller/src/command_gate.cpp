#include "ofn/controller/command_gate.hpp"

#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace ofn::control {
namespace {

std::string format(const char* pattern, double a, double b) {
  char text[160];
  std::snprintf(text, sizeof text, pattern, a, b);
  return text;
}

}  // namespace

void check_settings(const CommandGateSettings& s) {
  if (!(s.max_speed > 0) || !(s.max_vertical_speed > 0) || !(s.max_accel > 0))
    throw std::invalid_argument("command gate: airframe limits must be > 0");
  for (int i = 0; i < 3; ++i)
    if (!(s.fence_min[i] < s.fence_max[i]))
      throw std::invalid_argument(
          "command gate: the geofence's minimum must lie below its maximum");
  if (!(s.tolerance >= 0 && s.tolerance < 1))
    throw std::invalid_argument("command gate: tolerance must be in [0, 1)");
}

CommandGate::CommandGate(CommandGateSettings settings) : settings_(settings) {
  check_settings(settings_);
}

Limits CommandGate::airframe_limits() const {
  Limits l;
  l.max_speed = settings_.max_speed;
  l.max_vertical_speed = settings_.max_vertical_speed;
  l.max_accel = settings_.max_accel;
  return l;
}

bool CommandGate::inside_fence(const Vec3& p) const {
  for (int i = 0; i < 3; ++i)
    if (!(p[i] >= settings_.fence_min[i] && p[i] <= settings_.fence_max[i])) return false;
  return true;
}

std::optional<std::string> CommandGate::check_mission(
    const Limits& limits, const std::vector<Waypoint>& waypoints) const {
  const auto& s = settings_;
  if (!(limits.max_speed <= s.max_speed))
    return format("speed limit %.3g m/s above the airframe's %.3g m/s", limits.max_speed,
                  s.max_speed);
  if (!(limits.max_vertical_speed <= s.max_vertical_speed))
    return format("vertical speed limit %.3g m/s above the airframe's %.3g m/s",
                  limits.max_vertical_speed, s.max_vertical_speed);
  if (!(limits.max_accel <= s.max_accel))
    return format("acceleration limit %.3g m/s^2 above the airframe's %.3g m/s^2", limits.max_accel,
                  s.max_accel);
  for (size_t i = 0; i < waypoints.size(); ++i)
    if (!inside_fence(waypoints[i].position))
      return format("waypoint %.0f outside the geofence (%.0f m north)", static_cast<double>(i + 1),
                    waypoints[i].position.x());
  return std::nullopt;
}

std::optional<std::string> CommandGate::check_plan(const std::vector<double>& times,
                                                   const std::vector<Reference>& samples,
                                                   const Limits& limits, double from) const {
  if (times.size() != samples.size())
    throw std::invalid_argument("command gate: one time per plan sample");
  for (size_t k = 0; k < samples.size(); ++k) {
    if (k + 1 < samples.size() && times[k + 1] <= from) continue;  // past
    const Reference& r = samples[k];
    if (!inside_fence(r.position))
      return format("leaves the geofence at %.2f s (%.0f m north)", times[k], r.position.x());
    const EnvelopeShares shares = envelope_shares(r.velocity, r.acceleration, limits);
    if (!shares.within(settings_.tolerance))
      return format("leaves the envelope at %.2f s (%.2f of a limit)", times[k], shares.worst());
  }
  return std::nullopt;
}

Reference CommandGate::clamp(const Reference& reference, const Limits& limits,
                             bool* clamped) const {
  const double over = 1.0 + settings_.tolerance;
  Reference r = reference;
  // Into the fence; no motion further out at its faces.
  for (int i = 0; i < 3; ++i) {
    if (r.position[i] < settings_.fence_min[i]) {
      r.position[i] = settings_.fence_min[i];
      r.velocity[i] = std::max(0.0, r.velocity[i]);
      r.acceleration[i] = std::max(0.0, r.acceleration[i]);
    } else if (r.position[i] > settings_.fence_max[i]) {
      r.position[i] = settings_.fence_max[i];
      r.velocity[i] = std::min(0.0, r.velocity[i]);
      r.acceleration[i] = std::min(0.0, r.acceleration[i]);
    }
  }
  const double max_climb = over * limits.max_vertical_speed;
  if (std::abs(r.velocity.z()) > max_climb)
    r.velocity.z() = std::copysign(max_climb, r.velocity.z());
  const double max_speed = over * limits.max_speed;
  if (r.velocity.norm() > max_speed) r.velocity *= max_speed / r.velocity.norm();
  const double max_accel = over * limits.max_accel;
  if (r.acceleration.norm() > max_accel) r.acceleration *= max_accel / r.acceleration.norm();
  if (clamped)
    *clamped = (r.position - reference.position).norm() > 0 ||
               (r.velocity - reference.velocity).norm() > 0 ||
               (r.acceleration - reference.acceleration).norm() > 0;
  return r;
}

}  // namespace ofn::control
