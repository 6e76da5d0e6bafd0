#pragma once
// Global path search over the cuboid obstacle field (paper 4.2, Table 1,
// Eqs. 9-10): nodes around and on top of every cuboid at the clearance
// distance, merged and lifted out of other cuboids, a graph of straight
// segments whose cost is their length (blocked when a segment cuts a cuboid
// or its cubic approximation needs more than the acceleration limit), and
// dynamic programming for the shortest node sequence from the current
// position to the target waypoint. With a vertical speed limit a segment
// costs the time it takes to fly within both limits (as metres of level
// flight at `speed`): a climb steeper than the two limits allow costs
// more than its length (see GlobalPlannerConfig::vertical_speed). The coarse path warm-starts the
// RH optimiser and decides which way round (over or beside) it goes. Pure core: world NED, SI
// units, no LCM.

#include <limits>
#include <string>
#include <vector>

#include "ofn/common/frames.hpp"

namespace ofn::planning {

/// One cuboid of the obstacle database, axis-aligned in world NED.
struct ObstacleBox {
  int id = 0;
  Vec3 min_corner = Vec3::Zero();  // m; min_corner.z() is the top (NED z is down)
  Vec3 max_corner = Vec3::Zero();  // m; max_corner.z() is the bottom
  // False when the sensor never saw above it: the top is then a ceiling,
  // not a surface, and the planner never puts nodes on it.
  bool top_observed = true;
};

struct GlobalPlannerConfig {
  double clearance = 6.096;     // m, R_s: nodes sit this far outside every face
  double merge_distance = 3.0;  // m; nodes closer than this merge into one (step 3)
  double speed = 3.048;         // m/s, V of the Eq. 10 acceleration check
  double max_accel = 0.4877;    // m/s^2, limit of the Eq. 10 check
  /// m/s, the vertical speed limit; 0: a segment costs its length, as in the
  /// paper's Eq. 9. Above 0 it costs the least time to fly it within the
  /// speed and the vertical speed limits, in metres of level flight at
  /// `speed`: max(length, |rise| * speed / vertical_speed). At the
  /// benchmarks' 10 and 5 ft/s a climb steeper than 30 deg is bound by the
  /// vertical limit, and a way over a tall obstacle close by can take twice
  /// the time its length says (dense fields: routes 50 m up and down where
  /// the time-optimal flight went round).
  double vertical_speed = 0.0;
  // Eq. 10 assumes every segment starts and ends aligned with the leg. On
  // every segment that makes routes through offset gaps (bench6) or a
  // descent to a near goal (tree) "too sharp" although the optimiser flies
  // them within the limit by rounding the corners. By default only the
  // segments leaving the vehicle (with its real initial slope) are checked:
  // what the vehicle cannot reach from its present state; true checks all,
  // as the paper does.
  bool accel_check_all_segments = false;
  double ground_altitude = 0.0;       // m; the ground is at world z = -ground_altitude
  double min_altitude = 6.096;        // m above ground; no node lower
  double max_altitude = 150.0;        // m above ground; no node higher
  double path_spacing = 2.0;          // m between points of the interpolated path (step 8)
  double collision_tolerance = 0.05;  // m a segment may graze a clearance box by
  int max_obstacles = 500;            // more are ignored, nearest first kept
};

/// A region no segment may pass through, a vertical cylinder: a passage
/// the RH optimiser found it cannot fly (narrower in the mapped cells than
/// twice its clearance), although the cuboids leave it open. A start or
/// goal inside it sees it shrunk to its own distance, so it can leave.
struct NoGoZone {
  Vec3 centre = Vec3::Zero();  // m, world NED
  double radius = 0;           // m, horizontal
  double half_height = 0;      // m above and below the centre
};

enum class PlanStatus { kOk, kStartInside, kGoalInside, kNoPath };

const char* to_string(PlanStatus status);

struct PlanRequest {
  Vec3 start = Vec3::Zero();           // m, world NED: the vehicle now
  Vec3 start_velocity = Vec3::Zero();  // m/s; its direction is the first segment's initial slope
  Vec3 goal = Vec3::Zero();            // m, world NED: the target waypoint
  Vec3 leg_from = Vec3::Zero();  // m: previous waypoint; the guidance x axis is leg_from -> goal
  std::vector<ObstacleBox> obstacles;
  std::vector<NoGoZone> no_go;  // non-finite or non-positive ones are ignored
};

/// The graph of steps 1-6, for inspection and for checking the search.
struct PlanGraph {
  static constexpr double kBlocked = std::numeric_limits<double>::infinity();
  std::vector<Vec3> nodes;   // world NED; nodes[0] is the start, nodes[1] the goal
  std::vector<double> cost;  // nodes.size()^2, row-major: cost of the segment i -> j
  int size() const { return static_cast<int>(nodes.size()); }
  double at(int from, int to) const { return cost[static_cast<size_t>(from) * nodes.size() + to]; }
};

struct PlanResult {
  PlanStatus status = PlanStatus::kNoPath;
  /// m: the node path's cost, its length (or, with a vertical speed limit,
  /// its least flight time times `speed`)
  double cost = std::numeric_limits<double>::infinity();
  std::vector<Vec3> waypoints;  // chosen nodes, start first and goal last (world NED)
  std::vector<Vec3> path;       // waypoints interpolated every path_spacing (world NED)
  int nodes = 0;                // graph size after merging
  int segments_checked = 0;     // segments tested against the cuboids
  int ignored_obstacles = 0;    // cuboids skipped as non-finite, empty or beyond max_obstacles
  int blocking_obstacle = -1;   // id of the cuboid holding the start or the goal
};

class GlobalPlanner {
 public:
  /// Throws std::invalid_argument on a non-positive clearance, speed,
  /// max_accel or path_spacing, a negative or non-finite vertical_speed, or
  /// min_altitude >= max_altitude.
  explicit GlobalPlanner(GlobalPlannerConfig config = {});

  /// Steps 1-9 of Table 1. Throws std::invalid_argument if the start, its
  /// velocity, the goal or leg_from is not finite; bad cuboids are ignored
  /// and counted, never fatal.
  PlanResult plan(const PlanRequest& request);

  /// The same graph searched with segments in any direction and no Eq. 10
  /// check: the way out of a dead end, for a vehicle that stops first and
  /// may then turn back along the leg. Run it when plan() finds no path.
  PlanResult plan_any_direction(const PlanRequest& request);

  /// Steps 1-6 alone, every segment evaluated: the graph plan() searches.
  PlanGraph build_graph(const PlanRequest& request) const;

  const GlobalPlannerConfig& config() const { return config_; }

 private:
  PlanResult plan_with(const PlanRequest& request, bool any_direction);

  GlobalPlannerConfig config_;
};

}  // namespace ofn::planning
