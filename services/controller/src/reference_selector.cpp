#include "ofn/controller/reference_selector.hpp"

#include <sstream>

namespace ofn::control {

std::optional<std::string> ReferenceSelector::check_start(const Reference& offered,
                                                          const std::optional<Reference>& flown,
                                                          const Vec3& position,
                                                          const Vec3& velocity) const {
  if (!offered.position.allFinite() || !offered.velocity.allFinite() ||
      !offered.acceleration.allFinite())
    return std::string("non-finite start");
  const double off_vehicle = (offered.position - position).norm();
  const double off_vehicle_speed = (offered.velocity - velocity).norm();
  const bool on_vehicle =
      off_vehicle <= settings_.resync_position && off_vehicle_speed <= settings_.resync_velocity;
  if (!flown) {
    if (on_vehicle) return std::nullopt;
    std::ostringstream why;
    why.precision(3);
    why << "start " << off_vehicle << " m, " << off_vehicle_speed << " m/s off the vehicle";
    return why.str();
  }
  const double off_flown = (offered.position - flown->position).norm();
  const double off_flown_speed = (offered.velocity - flown->velocity).norm();
  if ((off_flown <= settings_.jump_position && off_flown_speed <= settings_.jump_velocity) ||
      on_vehicle)
    return std::nullopt;
  std::ostringstream why;
  why.precision(3);
  why << "start " << off_flown << " m, " << off_flown_speed << " m/s off the reference flown and "
      << off_vehicle << " m off the vehicle";
  return why.str();
}

Reference ReferenceSelector::safe_stop(double now, const Reference& flown, double max_accel) {
  if (!stop_) {
    stop_ = stop_from(flown.position, flown.velocity, flown.acceleration,
                      settings_.stop_accel_fraction * max_accel);
    stop_start_ = now;
  }
  Reference r = along(*stop_, now - stop_start_);
  r.yaw = flown.yaw;
  r.yaw_rate = flown.yaw_rate;
  return r;
}

Reference ReferenceSelector::hold(double now, const Vec3& position, const Vec3& velocity,
                                  bool begins) {
  if (begins) {
    hold_ = stop_from(position, velocity, settings_.hold_deceleration);
    hold_start_ = now;
  }
  return along(hold_, now - hold_start_);
}

Reference ReferenceSelector::along(const StopProfile& stop, double t) {
  Reference r;
  r.position = stop.position(t);
  r.velocity = stop.velocity_at(t);
  r.acceleration = stop.acceleration_at(t);
  return r;
}

}  // namespace ofn::control
