#pragma once
// The uplinked plan as the planners see it: waypoints and limits in SI from
// MISSION. Which leg the vehicle is on is LegTracker's (leg_tracker.hpp,
// pure), by the rule of the controller's waypoint guidance.

#include <vector>

#include "ofn/common/frames.hpp"
#include "ofn/common/mission_types.hpp"
#include "ofn/mission_t.hpp"

namespace ofn {

/// The uplink repeats the plan; only a new id (or scenario) is a new plan.
inline bool same_plan(const mission_t& a, const mission_t& b) {
  return a.mission_id == b.mission_id && a.name == b.name;
}

/// The message must have passed validate(mission_t).
inline std::vector<Waypoint> waypoints_from(const mission_t& m) {
  std::vector<Waypoint> out;
  for (const auto& w : m.waypoints) out.push_back({to_vec3(w.position), w.capture_radius});
  return out;
}

inline Limits limits_from(const limits_t& l) {
  return Limits{l.max_speed,         l.max_accel, l.max_vertical_speed,
                l.min_forward_speed, l.clearance, l.sensor_range};
}

}  // namespace ofn
