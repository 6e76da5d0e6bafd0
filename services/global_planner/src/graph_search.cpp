// The searches over a CuboidGraph (Eq. 9; see graph_search.hpp).

#include "ofn/global_planner/graph_search.hpp"

#include <algorithm>
#include <functional>
#include <limits>
#include <queue>

namespace ofn::planning {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

/// Node 0 -> node 1 by the parents the search closed them with; empty when
/// the goal (node 1) was never reached.
std::vector<int> sequence_to_goal(const std::vector<char>& closed, const std::vector<int>& parent) {
  if (!closed[1]) return {};
  std::vector<int> sequence;
  for (int v = 1; v >= 0; v = parent[v]) sequence.push_back(v);
  std::reverse(sequence.begin(), sequence.end());
  return sequence;
}

struct Entry {
  double f;  // cost so far plus the straight way's cost to the goal
  double g;
  int node;
  int parent;
  bool exhaustive;  // queued after the node's best candidate proved blocked
  bool operator>(const Entry& o) const { return f > o.f; }
};

}  // namespace

std::vector<int> search_forward(CuboidGraph& graph) {
  const int n = graph.size();
  const Vec3 goal = graph.nodes()[1];
  std::vector<double> h(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) h[i] = graph.segment_cost(graph.nodes()[i], goal);

  // Only nodes strictly between the start and the goal along the leg can
  // lie on a path; sorted along the leg so a closed node scans only those
  // ahead of it.
  std::vector<int> ahead;
  if (graph.goal_ahead()) {
    const double lo = graph.along(0) + kMinAdvance, hi = graph.along(1) - kMinAdvance;
    for (int i = 2; i < n; ++i)
      if (graph.along(i) > lo && graph.along(i) < hi) ahead.push_back(i);
  }
  ahead.push_back(1);
  std::sort(ahead.begin(), ahead.end(),
            [&](int a, int b) { return graph.along(a) < graph.along(b); });
  std::vector<double> ahead_x(ahead.size());
  for (size_t k = 0; k < ahead.size(); ++k) ahead_x[k] = graph.along(ahead[k]);

  std::vector<double> g(n, kInf), best_offer(n, kInf);
  std::vector<int> parent(n, -1), offer_parent(n, -1);
  std::vector<char> closed(n, 0), exhaustive(n, 0);
  std::vector<int> closed_list;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> open;

  auto close = [&](int v, double cost, int from) {
    closed[v] = 1;
    g[v] = cost;
    parent[v] = from;
    closed_list.push_back(v);
    const double x_from = graph.along(v) + kMinAdvance;
    auto first = std::upper_bound(ahead_x.begin(), ahead_x.end(), x_from) - ahead_x.begin();
    if (v == 0) first = 0;
    for (size_t k = static_cast<size_t>(first); k < ahead.size(); ++k) {
      const int w = ahead[k];
      if (closed[w]) continue;
      const double offer = cost + graph.cost(v, w);
      if (!exhaustive[w] && offer >= best_offer[w]) continue;
      if (!graph.shape_ok(v, w)) continue;
      if (!exhaustive[w]) {
        best_offer[w] = offer;
        offer_parent[w] = v;
      }
      open.push({offer + h[w], offer, w, v, exhaustive[w] != 0});
    }
  };

  close(0, 0.0, -1);
  while (!open.empty()) {
    const Entry e = open.top();
    open.pop();
    if (closed[e.node]) continue;
    // Stale: a better candidate replaced it, or it was queued before the
    // switch and its parent has been queued again since.
    if (exhaustive[e.node] ? !e.exhaustive
                           : (e.parent != offer_parent[e.node] || e.g != best_offer[e.node]))
      continue;
    if (!graph.blocked(e.parent, e.node)) {
      if (e.node == 1) {
        g[1] = e.g;
        parent[1] = e.parent;
        closed[1] = 1;
        break;
      }
      close(e.node, e.g, e.parent);
      continue;
    }
    if (exhaustive[e.node]) continue;
    exhaustive[e.node] = 1;
    for (int u : closed_list) {
      if (u == e.parent || !graph.shape_ok(u, e.node)) continue;
      const double offer = g[u] + graph.cost(u, e.node);
      open.push({offer + h[e.node], offer, e.node, u, true});
    }
  }
  return sequence_to_goal(closed, parent);
}

std::vector<int> search_any_direction(CuboidGraph& graph) {
  const int n = graph.size();
  const Vec3 goal = graph.nodes()[1];
  std::vector<int> parent(n, -1);
  std::vector<char> closed(n, 0);
  std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> open;
  // Closes v at `cost` by way of `from` and offers every open node from it
  // (the goal closes the search instead).
  auto close = [&](int v, double cost, int from) {
    closed[v] = 1;
    parent[v] = from;
    if (v == 1) return;
    for (int w = 1; w < n; ++w) {
      if (closed[w] || w == v) continue;
      const double offer = cost + graph.cost(v, w);
      open.push({offer + graph.segment_cost(graph.nodes()[w], goal), offer, w, v, false});
    }
  };
  close(0, 0.0, -1);
  while (!open.empty() && !closed[1]) {
    const Entry e = open.top();
    open.pop();
    if (!closed[e.node] && !graph.blocked(e.parent, e.node)) close(e.node, e.g, e.parent);
  }
  return sequence_to_goal(closed, parent);
}

}  // namespace ofn::planning
