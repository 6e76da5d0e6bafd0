#include "ofn/tools/arrival_watch.hpp"

#include <cstdio>
#include <cstdlib>

namespace ofn::report {

void ArrivalWatch::set_goal(int32_t mission_id, const Vec3& position, double capture_radius) {
  auto it = goals_.find(mission_id);
  if (it != goals_.end() && (it->second.position - position).norm() < 1e-9 &&
      it->second.capture_radius == capture_radius)
    return;
  // Bounded, so that a flood of mission ids cannot grow it: one goes, never
  // that of the mission the controller reports flying.
  if (it == goals_.end() && goals_.size() >= kMaxGoals) {
    auto victim = goals_.begin();
    if (victim->first == status_mission_) ++victim;
    goals_.erase(victim);
  }
  goals_[mission_id] = Goal{position, capture_radius};
  if (mission_id == done_mission_) done_since_ = INT64_MIN;
}

void ArrivalWatch::on_navigation(Utime stamp, const Vec3& position) {
  if (position_stamp_ != INT64_MIN && stamp < position_stamp_) return;  // reordered
  position_ = position;
  position_stamp_ = stamp;
}

std::optional<std::string> ArrivalWatch::doubt(Utime stamp, int32_t mission_id) const {
  const auto goal = goals_.find(mission_id);
  if (goal == goals_.end()) return "no mission " + std::to_string(mission_id) + " known";
  if (!position_ || std::llabs(stamp - position_stamp_) > to_utime(rules_.max_nav_age))
    return "no navigation at that time";
  const double distance = (*position_ - goal->second.position).norm();
  if (distance > goal->second.capture_radius + rules_.position_margin) {
    char text[96];
    std::snprintf(text, sizeof text, "vehicle %.1f m from the last waypoint", distance);
    return std::string(text);
  }
  return std::nullopt;
}

void ArrivalWatch::on_status(Utime stamp, bool done, int32_t mission_id) {
  status_mission_ = mission_id;
  if (arrived_at_) return;
  if (done) {
    if (const auto why = doubt(stamp, mission_id)) {
      ++unconfirmed_done_;
      last_doubt_ = *why;
      done_since_ = INT64_MIN;
      return;
    }
    if (done_since_ == INT64_MIN || stamp < done_since_ || mission_id != done_mission_)
      done_since_ = stamp;
    done_mission_ = mission_id;
    if (stamp - done_since_ >= to_utime(rules_.linger)) arrived_at_ = done_since_;
  } else {
    done_since_ = INT64_MIN;
  }
}

}  // namespace ofn::report
