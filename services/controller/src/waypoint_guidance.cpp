#include "ofn/controller/waypoint_guidance.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace ofn::control {
namespace {
// m; a vehicle this close to the leg is on it (no rejoin segment of
// vanishing length and undefined direction).
constexpr double kOnLegTolerance = 1e-3;
}  // namespace

void WaypointGuidance::set_mission(const std::vector<Waypoint>& waypoints, double cruise_speed,
                                   const Limits& limits, const Vec3& position,
                                   const Vec3& velocity) {
  waypoints_ = waypoints;
  // The cruise may not use the whole speed limit: the flown speed strays a
  // few tenths of a per cent from the reference, and the limit is hard.
  cruise_speed_ = limits.max_speed > 0
                      ? std::min(cruise_speed, config_.speed_fraction * limits.max_speed)
                      : cruise_speed;
  limits_ = limits;
  done_ = false;
  leg_cap_ = std::numeric_limits<int>::max();
  if (waypoints_.empty()) return;
  const int best = nearest_leg(waypoints_, position);
  const Vec3 from = best > 0 ? waypoints_[best - 1].position : position;
  start_leg(from, best, 0.0);
  resync(position, velocity);
}

void WaypointGuidance::start_leg(const Vec3& from, int to_index, double speed_along) {
  active_ = to_index;
  rejoin_.reset();
  leg_start_ = from;
  const Vec3 leg = waypoints_[to_index].position - from;
  leg_length_ = leg.norm();
  if (leg_length_ > 1e-6) leg_dir_ = leg / leg_length_;
  s_ = 0;
  s_dot_ = std::max(0.0, speed_along);
  s_ddot_ = 0;
}

void WaypointGuidance::back_on_leg() {
  leg_start_ = rejoin_->leg_start;
  leg_dir_ = rejoin_->leg_dir;
  leg_length_ = rejoin_->leg_length;
  rejoin_.reset();
}

void WaypointGuidance::join_leg() {
  const double beyond = std::max(0.0, s_ - leg_length_);
  const double meets_at = rejoin_->meets_at;
  s_dot_ *= std::max(0.0, leg_dir_.dot(rejoin_->leg_dir));
  back_on_leg();
  s_ = std::min(leg_length_, meets_at + beyond);
}

void WaypointGuidance::next_leg_from_reference() {
  const Vec3 ref_point = leg_start_ + leg_dir_ * s_;
  const Vec3 next = waypoints_[active_ + 1].position - ref_point;
  // Keep the part of the speed that lies along the new leg.
  const double carried =
      next.norm() > 1e-9 ? s_dot_ * std::max(0.0, leg_dir_.dot(next.normalized())) : 0.0;
  start_leg(ref_point, active_ + 1, carried);
}

bool WaypointGuidance::follow_leg(int index, bool flying, const Vec3& position,
                                  const Vec3& velocity) {
  if (waypoints_.empty() || active_ < 0 || index < 0 ||
      index >= static_cast<int>(waypoints_.size()))
    return false;
  leg_cap_ = index;
  if (index <= active_) return false;
  if (flying && index == active_ + 1) {
    next_leg_from_reference();
  } else {
    start_leg(waypoints_[index - 1].position, index, 0.0);
    resync(position, velocity);
  }
  return true;
}

void WaypointGuidance::resync(const Vec3& position, const Vec3& velocity) {
  if (waypoints_.empty() || active_ < 0) return;
  if (rejoin_) back_on_leg();  // measured from the leg itself, not from an earlier rejoin
  const double projection = std::clamp((position - leg_start_).dot(leg_dir_), 0.0, leg_length_);
  const Vec3 on_leg = leg_start_ + leg_dir_ * projection;
  if ((position - on_leg).norm() <= kOnLegTolerance) {
    s_ = projection;
  } else {
    // Put on the leg's line, the reference would step by the vehicle's
    // distance from it (a controller restarted after the vehicle drifted
    // for seconds: 2 m), and the vehicle would be pulled across at the
    // controller's bandwidth along a path nobody checked.
    const double meets_at = std::min(leg_length_, projection + kGuidanceRejoinDistance);
    const Vec3 segment = leg_start_ + leg_dir_ * meets_at - position;
    rejoin_ = Rejoin{leg_start_, leg_dir_, leg_length_, meets_at};
    leg_start_ = position;
    leg_length_ = segment.norm();
    leg_dir_ = segment / leg_length_;
    s_ = 0;
  }
  s_dot_ = std::clamp(velocity.dot(leg_dir_), 0.0, leg_speed_limit());
  s_ddot_ = 0;
  just_synced_ = true;
}

void WaypointGuidance::set_speed_reserve(double reserve) {
  speed_reserve_ = std::isfinite(reserve) ? std::max(0.0, reserve) : 0.0;
}

double WaypointGuidance::leg_speed_limit() const {
  double v = cruise_speed_;
  if (speed_reserve_ > 0 && limits_.max_speed > 0)
    v = std::min(v, std::max(0.0, config_.speed_fraction * limits_.max_speed - speed_reserve_));
  // Keep the climb or descent rate within its own limit.
  const double vertical = std::abs(leg_dir_.z());
  if (vertical > 1e-9) v = std::min(v, limits_.max_vertical_speed / vertical);
  return v;
}

GuidanceReference WaypointGuidance::update(const Vec3& position, const Vec3& velocity, double dt) {
  GuidanceReference out;
  if (waypoints_.empty() || active_ < 0) return out;
  if (just_synced_) dt = 0;
  just_synced_ = false;
  const double accel = config_.accel_fraction * limits_.max_accel;

  // Leg switching: inside the capture radius of an intermediate waypoint,
  // or with the reference at its end, fly on from where the reference is;
  // not past the planner's leg.
  while (!final_leg() && active_ < leg_cap_) {
    const Vec3& target = waypoints_[active_].position;
    const bool at_leg_end = !rejoin_ && s_ >= leg_length_ - 1e-9;
    if ((position - target).norm() > waypoints_[active_].capture_radius && !at_leg_end) break;
    next_leg_from_reference();
  }

  // To the waypoint: the rest of the rejoin, then the leg beyond it.
  const double remaining =
      leg_length_ - s_ + (rejoin_ ? rejoin_->leg_length - rejoin_->meets_at : 0.0);
  double target_speed = leg_speed_limit();
  // Rubber band: do not let the reference run away from a vehicle that lags.
  const double along = (position - leg_start_).dot(leg_dir_);
  const double lead = s_ - along;
  if (lead > config_.max_lead)
    target_speed *= std::clamp(1.0 - (lead - config_.max_lead) / config_.max_lead, 0.0, 1.0);

  // Distance used up while the deceleration ramps in at the jerk limit.
  const double jerk = config_.jerk_fraction * limits_.max_accel;
  const double ramp = s_dot_ * accel / (2.0 * jerk);
  double desired;
  if (final_leg() && remaining <= 1e-9) {
    desired = 0;
    s_dot_ = 0;
    s_ = leg_length_;
  } else if (final_leg() && s_dot_ * s_dot_ >= 2.0 * accel * std::max(remaining - ramp, 0.0)) {
    // Brake to stop at the last waypoint.
    desired = -std::min(accel, s_dot_ * s_dot_ / (2.0 * std::max(remaining - ramp, 1e-3)));
  } else {
    desired = std::clamp(config_.speed_gain * (target_speed - s_dot_), -accel, accel);
  }
  // Jerk limit: the acceleration reference never steps.
  s_ddot_ = std::clamp(desired, s_ddot_ - jerk * dt, s_ddot_ + jerk * dt);
  s_dot_ = std::max(0.0, s_dot_ + s_ddot_ * dt);
  if (s_dot_ == 0.0 && s_ddot_ < 0) s_ddot_ = 0;
  s_ += s_dot_ * dt;
  if (rejoin_ && s_ >= leg_length_) join_leg();
  s_ = std::min(leg_length_, s_);

  out.position = leg_start_ + leg_dir_ * s_;
  out.velocity = leg_dir_ * s_dot_;
  out.acceleration = leg_dir_ * s_ddot_;
  // The heading faces along the leg, through a rejoin too.
  out.leg_direction = rejoin_ ? rejoin_->leg_dir : leg_dir_;
  out.active_waypoint = active_;
  const Waypoint& last = waypoints_.back();
  if (final_leg() && !rejoin_ && s_ >= leg_length_ - 1e-6 &&
      (position - last.position).norm() <= last.capture_radius &&
      velocity.norm() <= config_.stop_speed)
    done_ = true;
  out.done = done_;
  return out;
}

}  // namespace ofn::control
