// Global path search (paper 4.2, Table 1): the graph of steps 1-6
// (cuboid_graph.hpp), the search of step 7 (graph_search.hpp: exact over the
// graph build_graph() evaluates in full, but testing only the segments it
// needs) and the path of step 8.

#include "ofn/global_planner/global_planner.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "ofn/global_planner/cuboid_graph.hpp"
#include "ofn/global_planner/graph_search.hpp"

namespace ofn::planning {

const char* to_string(PlanStatus status) {
  switch (status) {
    case PlanStatus::kOk:
      return "ok";
    case PlanStatus::kStartInside:
      return "start_inside";
    case PlanStatus::kGoalInside:
      return "goal_inside";
    case PlanStatus::kNoPath:
      return "no_path";
  }
  return "unknown";
}

namespace {

std::vector<Vec3> interpolate(const std::vector<Vec3>& waypoints, double spacing) {
  std::vector<Vec3> path;
  if (waypoints.empty()) return path;
  path.push_back(waypoints.front());
  for (size_t k = 1; k < waypoints.size(); ++k) {
    const Vec3& a = waypoints[k - 1];
    const Vec3& b = waypoints[k];
    const int steps = std::max(1, static_cast<int>(std::ceil((b - a).norm() / spacing)));
    for (int s = 1; s < steps; ++s) path.push_back(a + (b - a) * (static_cast<double>(s) / steps));
    path.push_back(b);
  }
  return path;
}

}  // namespace

GlobalPlanner::GlobalPlanner(GlobalPlannerConfig config) : config_(config) {
  const auto positive = [](double v) { return std::isfinite(v) && v > 0.0; };
  if (!positive(config_.clearance) || !positive(config_.speed) || !positive(config_.max_accel) ||
      !positive(config_.path_spacing))
    throw std::invalid_argument(
        "global planner: clearance, speed, max_accel and path_spacing must be positive");
  if (!(std::isfinite(config_.vertical_speed) && config_.vertical_speed >= 0.0))
    throw std::invalid_argument("global planner: vertical_speed must be 0 (off) or positive");
  if (!(config_.min_altitude < config_.max_altitude))
    throw std::invalid_argument("global planner: min_altitude must be below max_altitude");
}

PlanResult GlobalPlanner::plan(const PlanRequest& request) {
  return plan_with(request, /*any_direction=*/false);
}

PlanResult GlobalPlanner::plan_any_direction(const PlanRequest& request) {
  return plan_with(request, /*any_direction=*/true);
}

PlanResult GlobalPlanner::plan_with(const PlanRequest& request, bool any_direction) {
  CuboidGraph cuboid_graph(config_, request);
  PlanResult result;
  result.nodes = cuboid_graph.size();
  result.ignored_obstacles = cuboid_graph.ignored();
  if (cuboid_graph.start_holder() >= 0) {
    result.status = PlanStatus::kStartInside;
    result.blocking_obstacle = cuboid_graph.holder_id(cuboid_graph.start_holder());
    return result;
  }
  if (cuboid_graph.goal_holder() >= 0) {
    result.status = PlanStatus::kGoalInside;
    result.blocking_obstacle = cuboid_graph.holder_id(cuboid_graph.goal_holder());
    return result;
  }
  const std::vector<int> sequence =
      any_direction ? search_any_direction(cuboid_graph) : search_forward(cuboid_graph);
  result.segments_checked = cuboid_graph.segments_checked();
  if (sequence.empty()) {
    result.status = PlanStatus::kNoPath;
    return result;
  }
  result.status = PlanStatus::kOk;
  result.cost = 0.0;
  for (size_t k = 0; k < sequence.size(); ++k) {
    result.waypoints.push_back(cuboid_graph.nodes()[sequence[k]]);
    if (k > 0) result.cost += cuboid_graph.cost(sequence[k - 1], sequence[k]);
  }
  result.path = interpolate(result.waypoints, config_.path_spacing);
  return result;
}

PlanGraph GlobalPlanner::build_graph(const PlanRequest& request) const {
  CuboidGraph cuboid_graph(config_, request);
  PlanGraph graph;
  graph.nodes = cuboid_graph.nodes();
  const int n = cuboid_graph.size();
  graph.cost.assign(static_cast<size_t>(n) * n, PlanGraph::kBlocked);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      if (i == j || j == 0 || i == 1 || !cuboid_graph.shape_ok(i, j)) continue;
      if (!cuboid_graph.blocked(i, j))
        graph.cost[static_cast<size_t>(i) * n + j] = cuboid_graph.cost(i, j);
    }
  return graph;
}

}  // namespace ofn::planning
