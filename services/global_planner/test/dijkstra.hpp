#pragma once
// An independent check of the planner's searches: plain O(n^2) Dijkstra
// from node 0 to node 1 over any edge costs.

#include <algorithm>
#include <limits>
#include <vector>

namespace ofn::planning::test {

/// Length of the shortest path 0 -> 1 over n nodes; cost(u, v) is the
/// edge's length, infinity where there is none (asked once per pair at
/// most, and never for a node already settled). Infinity when 1 is not
/// reached.
template <class Cost>
double dijkstra(int n, Cost&& cost) {
  constexpr double kNone = std::numeric_limits<double>::infinity();
  std::vector<double> dist(n, kNone);
  std::vector<char> done(n, 0);
  dist[0] = 0.0;
  for (int round = 0; round < n; ++round) {
    int u = -1;
    for (int i = 0; i < n; ++i)
      if (!done[i] && (u < 0 || dist[i] < dist[u])) u = i;
    if (u < 0 || dist[u] == kNone) break;
    done[u] = 1;
    for (int v = 0; v < n; ++v)
      if (!done[v]) dist[v] = std::min(dist[v], dist[u] + cost(u, v));
  }
  return dist[1];
}

}  // namespace ofn::planning::test
