#pragma once
// Content checks for every message type. Each returns an empty string when
// the message is acceptable and otherwise a short reason that the node
// counts and logs. Time (staleness) is checked by the node, not here.

#include <cmath>
#include <string>

#include "ofn/actuator_cmd_t.hpp"
#include "ofn/control_status_t.hpp"
#include "ofn/cuboid_list_t.hpp"
#include "ofn/global_path_t.hpp"
#include "ofn/heartbeat_t.hpp"
#include "ofn/lidar_scan_t.hpp"
#include "ofn/mission_t.hpp"
#include "ofn/narrow_passages_t.hpp"
#include "ofn/nav_state_t.hpp"
#include "ofn/obstacle_grid_t.hpp"
#include "ofn/ref_traj_t.hpp"
#include "ofn/scan_world_t.hpp"
#include "ofn/sim_clock_t.hpp"
#include "ofn/solver_stats_t.hpp"
#include "ofn/virtual_obstacles_t.hpp"

namespace ofn {

/// Size bounds: a message larger than these is rejected as implausible.
struct MessageLimits {
  static constexpr int kMaxWaypoints = 1000;
  static constexpr int kMaxObstacles = 10000;
  static constexpr int kMaxBeams = 20000;
  static constexpr int kMaxScanPoints = 200000;
  static constexpr int kMaxGridCells = 4000000;
  static constexpr int kMaxCuboids = 10000;
  static constexpr int kMaxPathPoints = 10000;
  static constexpr int kMaxTrajSamples = 20000;
  static constexpr int kMaxSplineKnots = 1000;
  static constexpr int kMaxPassages = 1000;
  /// Positions farther than this from the origin are not from this mission.
  static constexpr double kMaxCoordinate = 1.0e6;
};

template <class It>
bool all_finite(It first, It last) {
  for (; first != last; ++first)
    if (!std::isfinite(static_cast<double>(*first))) return false;
  return true;
}
template <class T, size_t N>
bool all_finite(const T (&array)[N]) {
  return all_finite(array, array + N);
}

std::string validate(const nav_state_t& msg);
std::string validate(const actuator_cmd_t& msg);
std::string validate(const sim_clock_t& msg);
std::string validate(const mission_t& msg);
std::string validate(const virtual_obstacles_t& msg);
std::string validate(const lidar_scan_t& msg);
std::string validate(const scan_world_t& msg);
std::string validate(const obstacle_grid_t& msg);
std::string validate(const cuboid_list_t& msg);
std::string validate(const global_path_t& msg);
std::string validate(const narrow_passages_t& msg);
std::string validate(const ref_traj_t& msg);
std::string validate(const solver_stats_t& msg);
std::string validate(const control_status_t& msg);
std::string validate(const heartbeat_t& msg);

}  // namespace ofn
