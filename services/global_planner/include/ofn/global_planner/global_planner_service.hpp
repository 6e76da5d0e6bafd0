#pragma once
// Binds the global planner to the bus: CUBOIDS, NAV_STATE, MISSION and
// NARROW_PASSAGES (what the RH optimiser could not fly through) in,
// GLOBAL_PATH out once a second and whenever the cuboid set or the target
// waypoint changes (paper 4.2: the coarse route that warm-starts the RH
// optimiser). Clearance, acceleration limit and speed come from the
// mission's limits, so the route is checked against what will be flown.

#include <optional>
#include <vector>

#include "ofn/common/config.hpp"
#include "ofn/common/leg_tracker.hpp"
#include "ofn/common/mission_plan.hpp"
#include "ofn/common/node.hpp"
#include "ofn/control_status_t.hpp"
#include "ofn/cuboid_list_t.hpp"
#include "ofn/global_path_t.hpp"
#include "ofn/global_planner/global_planner.hpp"
#include "ofn/mission_t.hpp"
#include "ofn/narrow_passages_t.hpp"
#include "ofn/nav_state_t.hpp"

namespace ofn::planning {

struct GlobalPlannerServiceConfig {
  double replan_rate = 1.0;      // Hz (paper: 1 s)
  double nav_max_age = 0.5;      // s; older NAV_STATE is stale
  double cuboids_max_age = 5.0;  // s; without fresher CUBOIDS no route is published
  // Core settings not taken from the mission (clearance, max_accel, speed
  // and vertical_speed are).
  double merge_distance = 3.0;
  double ground_altitude = 0.0;
  double min_altitude = 6.096;
  double max_altitude = 150.0;
  double path_spacing = 2.0;
  double collision_tolerance = 0.05;
  int max_obstacles = 500;
  /// Segments cost their flight time within the mission's speed and
  /// vertical speed limits (GlobalPlannerConfig::vertical_speed); false:
  /// their length, as in the paper's Eq. 9.
  bool time_cost = false;
};

/// Reads a global_planner config; unknown fields are errors.
GlobalPlannerServiceConfig load_global_planner_config(YamlReader& reader);

/// The core's settings for a mission: clearance, acceleration limit and
/// cruise speed from the plan, the rest from the service config.
GlobalPlannerConfig planner_config_for(const GlobalPlannerServiceConfig& config,
                                       const mission_t& mission);

std::vector<ObstacleBox> boxes_from(const cuboid_list_t& msg);

/// The no-go zones of a NARROW_PASSAGES message (validated).
std::vector<NoGoZone> zones_from(const narrow_passages_t& msg);

/// GLOBAL_PATH of a plan; with NO_PATH, `points` carry the geometric route
/// if one was found (a guess for the optimiser, not a flyable plan), or
/// else, with BACKTRACK, the route in any direction (out of a dead end).
global_path_t path_message(const PlanResult& result, Utime utime,
                           const PlanResult* geometric_route = nullptr,
                           const PlanResult* backtrack_route = nullptr);

class GlobalPlannerService {
 public:
  GlobalPlannerService(lcm::LCM& lcm, const Clock& clock, GlobalPlannerServiceConfig config);
  Node& node() { return node_; }
  /// The last plan published (empty before the first).
  const std::optional<PlanResult>& last_plan() const { return last_plan_; }
  int64_t plans() const { return plans_; }

 private:
  void on_nav(const nav_state_t& m);
  void on_mission(const mission_t& m);
  void on_cuboids(const cuboid_list_t& m);
  void on_passages(const narrow_passages_t& m);
  void replan(const char* why);

  Node node_;
  GlobalPlannerServiceConfig config_;
  std::optional<GlobalPlanner> planner_;
  // The same search without the Eq. 10 check: when no route is flyable
  // within the acceleration limit, the shortest collision-free one still
  // tells the optimiser which way round to look (sent with NO_PATH).
  std::optional<GlobalPlanner> geometric_planner_;
  std::optional<nav_state_t> nav_;
  std::optional<mission_t> mission_;
  std::optional<cuboid_list_t> cuboids_;
  // The passages of the current mission the optimiser could not fly.
  std::vector<NoGoZone> no_go_;
  LegTracker legs_;
  int active_leg_ = -1;
  std::optional<PlanResult> last_plan_;
  bool last_backtracks_ = false;  // the last plan published was BACKTRACK
  int64_t plans_ = 0;
};

}  // namespace ofn::planning
