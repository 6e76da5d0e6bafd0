#pragma once
// The searches over a CuboidGraph (Eq. 9): best-first with the cost of the
// straight way to the goal as the (consistent) estimate, and a segment tested
// against the cuboids only when it is about to fix a node's cost, so the
// result is that of dynamic programming over the graph evaluated in full
// (GlobalPlanner::build_graph) while only a few segments are tested.
// Pure core.

#include <vector>

#include "ofn/global_planner/cuboid_graph.hpp"

namespace ofn::planning {

/// Shortest node sequence 0 -> 1 over the segments that advance along the
/// leg and pass shape_ok(); empty when the goal is not reached. Each open
/// node first carries only its best candidate parent; after that one proves
/// blocked, every closed parent is queued for it, so no blocked segment is
/// ever tested twice.
std::vector<int> search_forward(CuboidGraph& graph);

/// Shortest node sequence 0 -> 1 with segments in any direction and no
/// Eq. 10 check: the way out of a dead end, which turns back along the leg
/// and which search_forward() cannot find; the vehicle starts it from a
/// hover. Empty when the goal is not reached.
std::vector<int> search_any_direction(CuboidGraph& graph);

}  // namespace ofn::planning
