#pragma once
// What a mission asks of the flight code: the envelope (paper Eq. 8 and
// the safety radius R_s) and the waypoints, SI and world NED. Pure types;
// a scenario file (ofn/common/scenario.hpp) and a MISSION message both
// become these.

#include <limits>
#include <vector>

#include "ofn/common/frames.hpp"

namespace ofn {

struct Limits {
  double max_speed = 0;           // m/s
  double max_accel = 0;           // m/s^2, total
  double max_vertical_speed = 0;  // m/s
  double min_forward_speed = 0;   // m/s
  double clearance = 0;           // m
  double sensor_range = 0;        // m
};

struct Waypoint {
  Vec3 position = Vec3::Zero();  // m, world NED
  double capture_radius = 0;     // m
};

/// Legs closer to `position` than the nearest by less than this count as
/// equally near (the two legs of a route flown out and back lie on one
/// line, and their distances differ in the last bits).
inline constexpr double kLegTieDistance = 1e-3;  // m

/// How nominal waypoint guidance takes up a leg from a vehicle that is off
/// it (a restarted controller, the end of a stop, a hold or an avoidance):
/// a straight rejoin from the vehicle to the leg this far ahead of the
/// vehicle's projection on it (or to the leg's end, if nearer), then the
/// leg. The RH optimiser checks exactly that path before guidance may fly
/// (rh::check_nominal_path): one value for both.
inline constexpr double kGuidanceRejoinDistance = 15.0;  // m

/// Index of the waypoint that ends the leg nearest `position`; 0 for a
/// single waypoint, -1 for none. Of equally near legs the earliest wins: a
/// route that comes back over itself is flown outwards first, and a
/// vehicle on the waypoint between two legs moves on by the capture rule
/// of whoever picks the leg up. Where a plan is picked up mid-route (the
/// start, a restarted controller, the planners).
inline int nearest_leg(const std::vector<Waypoint>& waypoints, const Vec3& position) {
  if (waypoints.empty()) return -1;
  int best = 0;
  double best_distance = std::numeric_limits<double>::infinity();
  for (size_t i = 1; i < waypoints.size(); ++i) {
    const double d =
        distance_to_segment(position, waypoints[i - 1].position, waypoints[i].position);
    if (d < best_distance - kLegTieDistance) {
      best_distance = d;
      best = static_cast<int>(i);
    }
  }
  return best;
}

}  // namespace ofn
