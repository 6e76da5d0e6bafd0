#pragma once
// Steps 1-6 of Table 1 for one request: the cuboids kept, the nodes placed
// round and on top of them (merged, lifted out of other cuboids), and the
// segment tests the search asks for one at a time (Eq. 10 shape, cuboids,
// no-go zones). Everything here lives for one call only (step 9).
// Pure core: world NED, SI units.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <utility>
#include <vector>

#include "ofn/global_planner/box_grid.hpp"
#include "ofn/global_planner/global_planner.hpp"

namespace ofn::planning {

/// A segment must gain this much along the leg (forward speed >= 0 with
/// some margin, and Eq. 10 divides by the gain).
inline constexpr double kMinAdvance = 0.1;  // m

class CuboidGraph {
 public:
  /// Throws std::invalid_argument if the start, its velocity, the goal or
  /// leg_from is not finite. Invalid cuboids and no-go zones are skipped
  /// (the cuboids counted in ignored()).
  CuboidGraph(const GlobalPlannerConfig& config, const PlanRequest& request);

  /// Cuboids skipped: invalid, or beyond max_obstacles (the farthest).
  int ignored() const { return ignored_; }
  /// Index among the kept cuboids of the first holding the start (or the
  /// goal) inside its raw box; -1 when none.
  int start_holder() const { return start_holder_; }
  int goal_holder() const { return goal_holder_; }
  /// The database id of the kept cuboid `kept_index`.
  int holder_id(int kept_index) const { return boxes_[kept_index].id; }

  /// Node 0 is the start, node 1 the goal, the rest corners and tops.
  const std::vector<Vec3>& nodes() const { return nodes_; }
  int size() const { return static_cast<int>(nodes_.size()); }
  /// m: node i's distance along the leg (guidance x).
  double along(int i) const { return along_[i]; }
  /// Segments tested against the cuboids so far.
  int segments_checked() const { return segments_checked_; }

  double length(int i, int j) const { return (nodes_[j] - nodes_[i]).norm(); }
  /// What the search minimises for i -> j: segment_cost() of the two nodes.
  double cost(int i, int j) const { return segment_cost(nodes_[i], nodes_[j]); }
  /// The cost of a straight segment a -> b: its length, or with a vertical
  /// speed limit max(length, |rise| * speed / vertical_speed). A metric
  /// (the larger of two), so the cost of the straight way to the goal is a
  /// consistent estimate for the search.
  double segment_cost(const Vec3& a, const Vec3& b) const {
    const double length = (b - a).norm();
    if (!(config_.vertical_speed > 0)) return length;
    return std::max(length, std::abs(b.z() - a.z()) * config_.speed / config_.vertical_speed);
  }

  /// Whether i -> j is a segment of the graph apart from the cuboids: it
  /// advances along the leg and passes the Eq. 10 check.
  bool shape_ok(int i, int j) const;

  /// When the goal is not ahead of the start along the leg, the only
  /// segment is the direct one (a vehicle that overshot still gets a path).
  bool goal_ahead() const { return guidance_[1].x() - guidance_[0].x() > kMinAdvance; }

  /// Whether i -> j cuts a cuboid (clearance box shrunk by the tolerance,
  /// or less around a start or goal that is already inside it) or comes
  /// inside a no-go zone (likewise relieved).
  bool blocked(int i, int j);

 private:
  std::vector<Aabb> keep_boxes(const std::vector<ObstacleBox>& obstacles);
  void find_holders();
  std::vector<double> reliefs(const Vec3& p) const;
  std::vector<double> zone_reliefs(const Vec3& p) const;
  double ground_z(double altitude) const { return -(config_.ground_altitude + altitude); }
  double line_z(double x, double y) const;
  void place_nodes();
  void add_line_crossings(const Aabb& c, double z, std::vector<Vec3>& out) const;
  bool lift_out(Vec3& p) const;
  void add_to_merge_index(int i);
  bool has_neighbour(const Vec3& p) const;

  const GlobalPlannerConfig& config_;
  GuidanceFrame frame_;
  Vec3 start_, goal_;
  std::pair<double, double> start_slopes_{0.0, 0.0};
  int ignored_ = 0;
  std::vector<ObstacleBox> boxes_;
  std::vector<Aabb> raw_, clear_, solid_;
  BoxGrid grid_;
  std::vector<double> relief_start_, relief_goal_;
  std::vector<NoGoZone> zones_;
  std::vector<double> zone_relief_start_, zone_relief_goal_;
  int start_holder_ = -1, goal_holder_ = -1;
  std::vector<Vec3> nodes_, guidance_;
  std::vector<double> along_;
  std::unordered_map<int64_t, std::vector<int>> merge_index_;
  std::vector<uint32_t> stamp_;
  uint32_t query_ = 0;
  int segments_checked_ = 0;
};

}  // namespace ofn::planning
