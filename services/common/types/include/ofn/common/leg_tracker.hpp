#pragma once
// Which leg of the mission the vehicle is on, as the planners see it: the
// same rule as the controller's waypoint guidance. Start on the leg nearest
// the vehicle (nearest_leg), move on inside a waypoint's capture radius or
// once past the waypoint along the leg. The controller's word
// (CONTROL_STATUS.active_waypoint) moves a planner on too: where legs lie
// over each other (a route flown out and back) the vehicle's position alone
// cannot tell them apart, and a planner picked up mid-route would otherwise
// watch a leg the controller is not flying. Pure: world NED, SI.

#include <optional>
#include <utility>
#include <vector>

#include "ofn/common/frames.hpp"
#include "ofn/common/mission_types.hpp"

namespace ofn {

struct ActiveLeg {
  Vec3 from = Vec3::Zero();   // previous waypoint (or where the plan was picked up)
  Vec3 to = Vec3::Zero();     // the waypoint flown to
  int index = -1;             // index of `to` in the plan
  bool final = false;         // `to` is the last waypoint
  double capture_radius = 0;  // m, of `to`
};

class LegTracker {
 public:
  /// Starts plan `plan_id` at the leg nearest `position` (ties go to the
  /// earliest leg; update() then moves on past a waypoint already reached).
  void set_plan(int plan_id, std::vector<Waypoint> waypoints, const Vec3& position) {
    plan_id_ = plan_id;
    waypoints_ = std::move(waypoints);
    active_ = nearest_leg(waypoints_, position);
    single_from_ = position;  // where a single-waypoint plan's leg starts
  }

  void clear() {
    waypoints_.clear();
    active_ = -1;
  }
  bool has_plan() const { return active_ >= 0; }

  /// The controller flies to waypoint `index` of plan `plan_id`: a leg
  /// further on is taken up, never one behind (the planners may move on
  /// first: the controller's guidance does not advance while it flies
  /// their plan). Another plan's word, or an index outside this plan, is
  /// ignored. Returns whether the leg changed.
  bool follow(int plan_id, int index) {
    if (!has_plan() || plan_id != plan_id_) return false;
    if (index <= active_ || index >= static_cast<int>(waypoints_.size())) return false;
    active_ = index;
    return true;
  }

  /// Moves on past every waypoint captured or passed; the leg now flown.
  std::optional<ActiveLeg> update(const Vec3& position) {
    if (active_ < 0) return std::nullopt;
    while (active_ + 1 < static_cast<int>(waypoints_.size()) && reached(position)) ++active_;
    ActiveLeg leg;
    leg.index = active_;
    leg.to = waypoints_[active_].position;
    leg.from = active_ > 0 ? waypoints_[active_ - 1].position : single_from_;
    leg.final = active_ + 1 == static_cast<int>(waypoints_.size());
    leg.capture_radius = waypoints_[active_].capture_radius;
    return leg;
  }

 private:
  bool reached(const Vec3& position) const {
    const Waypoint& target = waypoints_[active_];
    if ((position - target.position).norm() <= target.capture_radius) return true;
    if (active_ == 0) return false;
    const Vec3 from = waypoints_[active_ - 1].position;
    const Vec3 leg = target.position - from;
    const double length = leg.norm();
    return length > 1e-9 && (position - from).dot(leg / length) >= length;
  }

  int plan_id_ = -1;
  std::vector<Waypoint> waypoints_;
  int active_ = -1;
  Vec3 single_from_ = Vec3::Zero();
};

}  // namespace ofn
