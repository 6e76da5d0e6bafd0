// The global planner's parts alone: box geometry and the bucket grid
// against brute force, the nodes the graph places round one cuboid, the
// relief a start inside a clearance box gets, and the any-direction search
// against a plain Dijkstra over every segment the graph allows.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <set>
#include <vector>

#include "dijkstra.hpp"
#include "ofn/global_planner/box_grid.hpp"
#include "ofn/global_planner/cuboid_graph.hpp"
#include "ofn/global_planner/graph_search.hpp"

namespace ofn::planning {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();
constexpr double kFlightAltitude = 36.6;  // m

ObstacleBox cuboid(int id, Vec3 min_corner, Vec3 max_corner, bool top_observed = true) {
  ObstacleBox b;
  b.id = id;
  b.min_corner = min_corner;
  b.max_corner = max_corner;
  b.top_observed = top_observed;
  return b;
}

PlanRequest request_along_north(std::vector<ObstacleBox> obstacles) {
  PlanRequest r;
  r.start = Vec3(0.0, 0.0, -kFlightAltitude);
  r.leg_from = r.start;
  r.goal = Vec3(100.0, 0.0, -kFlightAltitude);
  r.obstacles = std::move(obstacles);
  return r;
}

// Whether p -> q meets the box, by fine sampling (the brute force the slab
// test is checked against; segments that only graze a face are avoided).
bool sampled_meets(const Aabb& box, const Vec3& p, const Vec3& q) {
  for (int k = 0; k <= 20000; ++k) {
    const Vec3 x = p + (q - p) * (k / 20000.0);
    if ((x.array() >= box.lo.array()).all() && (x.array() <= box.hi.array()).all()) return true;
  }
  return false;
}

TEST(BoxGeometry, SlabTestAgreesWithSamplingOnRandomSegments) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> coordinate(-20.0, 20.0);
  const Aabb box{Vec3(-5, -3, -8), Vec3(4, 6, 2)};
  int meeting = 0, missing = 0;
  for (int trial = 0; trial < 400; ++trial) {
    const Vec3 p(coordinate(rng), coordinate(rng), coordinate(rng));
    const Vec3 q(coordinate(rng), coordinate(rng), coordinate(rng));
    const bool meets = segment_meets(box, p, q);
    // Far from grazing: the box shrunk and grown by 5 cm give the same answer.
    if (segment_meets(inflated(box, -0.05), p, q) != segment_meets(inflated(box, 0.05), p, q))
      continue;
    EXPECT_EQ(meets, sampled_meets(box, p, q)) << p.transpose() << " -> " << q.transpose();
    (meets ? meeting : missing) += 1;
  }
  // Both answers were exercised.
  EXPECT_GT(meeting, 50);
  EXPECT_GT(missing, 50);
}

TEST(BoxGeometry, InsideAndOutsideDistance) {
  const Aabb box{Vec3(0, 0, 0), Vec3(10, 4, 2)};
  EXPECT_TRUE(strictly_inside(box, Vec3(5, 2, 1)));
  EXPECT_FALSE(strictly_inside(box, Vec3(0, 2, 1)));  // on a face
  EXPECT_DOUBLE_EQ(outside_distance(box, Vec3(5, 2, 1)), 0.0);
  EXPECT_DOUBLE_EQ(outside_distance(box, Vec3(13, 2, 1)), 3.0);
  // Chebyshev: the largest gap of the three axes.
  EXPECT_DOUBLE_EQ(outside_distance(box, Vec3(12, 9, -1)), 5.0);
  // A segment parallel to an axis, beside the box and through it.
  EXPECT_FALSE(segment_meets(box, Vec3(-5, 5, 1), Vec3(15, 5, 1)));
  EXPECT_TRUE(segment_meets(box, Vec3(-5, 3, 1), Vec3(15, 3, 1)));
  // A point: meets only inside or on the box.
  EXPECT_TRUE(segment_meets(box, Vec3(1, 1, 1), Vec3(1, 1, 1)));
  EXPECT_FALSE(segment_meets(box, Vec3(-1, 1, 1), Vec3(-1, 1, 1)));
}

TEST(BoxGrid, EverySegmentMeetsAtLeastTheBoxesItsProjectionCrosses) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> where(-100.0, 100.0), size(1.0, 25.0);
  for (int boxes_count : {1, 3, 40, 400}) {
    std::vector<Aabb> boxes;
    for (int i = 0; i < boxes_count; ++i) {
      const Vec3 lo(where(rng), where(rng), -size(rng));
      boxes.push_back({lo, lo + Vec3(size(rng), size(rng), -lo.z())});
    }
    const BoxGrid grid(boxes);
    int crossings = 0;
    for (int trial = 0; trial < 300; ++trial) {
      const Vec3 p(where(rng) * 1.3, where(rng) * 1.3, -1.0);
      const Vec3 q = trial % 10 == 0 ? p : Vec3(where(rng) * 1.3, where(rng) * 1.3, -1.0);
      std::set<int> visited;
      grid.along_segment(p, q, [&](int b) { visited.insert(b); });
      for (int b = 0; b < boxes_count; ++b) {
        // The footprint, as a box of all heights.
        const Aabb column{Vec3(boxes[b].lo.x(), boxes[b].lo.y(), -1e6),
                          Vec3(boxes[b].hi.x(), boxes[b].hi.y(), 1e6)};
        if (!segment_meets(column, p, q)) continue;
        ++crossings;
        EXPECT_EQ(visited.count(b), 1u) << "box " << b << " of " << boxes_count;
      }
    }
    EXPECT_GT(crossings, 0) << boxes_count << " boxes";
  }
}

TEST(BoxGrid, NoBoxesVisitNothing) {
  const BoxGrid grid({});
  int visits = 0;
  grid.along_segment(Vec3(0, 0, 0), Vec3(50, 50, 0), [&](int) { ++visits; });
  EXPECT_EQ(visits, 0);
}

TEST(CuboidGraph, NodesSitAtTheClearanceRoundAndOnTopOfOneCuboid) {
  GlobalPlannerConfig config;
  config.merge_distance = 0.0;  // every node kept, so the count is exact
  const double rs = config.clearance;
  // 20 m tall, 10 x 8 m, across the leg.
  const ObstacleBox box = cuboid(4, Vec3(40, -4, -20), Vec3(50, 4, 0));
  const CuboidGraph graph(config, request_along_north({box}));
  EXPECT_EQ(graph.start_holder(), -1);
  EXPECT_EQ(graph.goal_holder(), -1);
  EXPECT_EQ(graph.ignored(), 0);
  const auto& nodes = graph.nodes();
  EXPECT_TRUE(nodes[0].isApprox(Vec3(0, 0, -kFlightAltitude)));
  EXPECT_TRUE(nodes[1].isApprox(Vec3(100, 0, -kFlightAltitude)));
  // Four corners at the leg's altitude, four on top, two where the leg
  // crosses the footprint on top.
  ASSERT_EQ(graph.size(), 12);
  int at_altitude = 0, on_top = 0;
  for (int i = 2; i < graph.size(); ++i) {
    const Vec3& p = nodes[i];
    EXPECT_TRUE(std::abs(p.x() - (40 - rs)) < 1e-9 || std::abs(p.x() - (50 + rs)) < 1e-9 ||
                std::abs(p.y()) < 1e-9)
        << p.transpose();
    if (std::abs(p.z() + kFlightAltitude) < 1e-9) ++at_altitude;
    if (std::abs(p.z() - (-20 - rs)) < 1e-9) ++on_top;
    EXPECT_DOUBLE_EQ(graph.along(i), p.x());
  }
  EXPECT_EQ(at_altitude, 4);
  EXPECT_EQ(on_top, 6);

  // A top no beam went over gets no nodes on it.
  const CuboidGraph unseen(
      config, request_along_north({cuboid(4, Vec3(40, -4, -20), Vec3(50, 4, 0), false)}));
  EXPECT_EQ(unseen.size(), 6);
}

TEST(CuboidGraph, CornersOfTwoCuboidsThatAlmostMeetMergeIntoOne) {
  GlobalPlannerConfig config;
  const double rs = config.clearance;
  // 2 R_s + 0.3 m apart: their facing corners lie 0.3 m from each other
  // (and 8.6 m from where the leg crosses b's top).
  const ObstacleBox a = cuboid(1, Vec3(40, -30, -10), Vec3(50, -15, 0));
  const ObstacleBox b = cuboid(2, Vec3(40, -15 + 2 * rs + 0.3, -10), Vec3(50, 30, 0));
  config.merge_distance = 0.0;
  const int unmerged = CuboidGraph(config, request_along_north({a, b})).size();
  config.merge_distance = 3.0;
  const int merged = CuboidGraph(config, request_along_north({a, b})).size();
  // Two pairs at the leg's altitude and two on top.
  EXPECT_EQ(unmerged - merged, 4);
}

TEST(CuboidGraph, CornersInsideAnotherCuboidsClearanceGoOntoItsTop) {
  GlobalPlannerConfig config;
  config.merge_distance = 0.0;  // every lifted node kept, so the count is exact
  // 1 m apart, both taller than the leg's altitude; b is longer, so a's
  // corners facing it lie inside its clearance.
  const double rs = config.clearance;
  const ObstacleBox a = cuboid(1, Vec3(40, -20, -60), Vec3(50, -5, 0));
  const ObstacleBox b = cuboid(2, Vec3(35, -4, -70), Vec3(55, 10, 0));
  const CuboidGraph graph(config, request_along_north({a, b}));
  int lifted = 0;
  for (const Vec3& p : graph.nodes()) {
    for (const ObstacleBox& box : {a, b}) {
      const Aabb solid =
          inflated({box.min_corner, box.max_corner}, config.clearance - config.collision_tolerance);
      EXPECT_FALSE(strictly_inside(solid, p)) << p.transpose();
    }
    // a's corners (at the leg's altitude and on a's top, both ends), on
    // b's top plus R_s.
    if (std::abs(p.y() - (-5 + rs)) < 1e-9 && std::abs(p.z() - (-70 - rs)) < 1e-9) ++lifted;
  }
  EXPECT_EQ(lifted, 4);
}

TEST(CuboidGraph, AStartInsideTheClearanceMayLeaveButNotCrossTheCuboid) {
  GlobalPlannerConfig config;
  const ObstacleBox box = cuboid(3, Vec3(10, -4, -60), Vec3(20, 4, 0));
  PlanRequest request = request_along_north({box});
  request.start = Vec3(8.0, 10.0, -kFlightAltitude);  // 2 m from the box, within R_s
  request.leg_from = request.start;
  CuboidGraph graph(config, request);
  EXPECT_EQ(graph.start_holder(), -1);  // not inside the box itself
  // Away from the box: allowed although it starts within R_s.
  int away = -1;
  for (int i = 2; i < graph.size(); ++i)
    if (graph.nodes()[i].y() > 10.0 && graph.nodes()[i].x() > 8.0) away = i;
  ASSERT_GE(away, 0);
  EXPECT_FALSE(graph.blocked(0, away));
  // Straight to the goal, through the box: blocked.
  EXPECT_TRUE(graph.blocked(0, 1));
  EXPECT_EQ(graph.segments_checked(), 2);
}

// Dijkstra over every segment the graph's blocked() allows, any direction.
double dijkstra_any_direction(CuboidGraph& graph) {
  return test::dijkstra(graph.size(), [&](int u, int v) {
    return v == 0 || v == u || graph.blocked(u, v) ? kInfinity : graph.cost(u, v);
  });
}

void expect_any_direction_optimal(double vertical_speed);

TEST(GraphSearch, AnyDirectionFindsWhatDijkstraFindsAndNeverCostsMoreThanForward) {
  // Segments costing their length, and their flight time within a
  // vertical speed limit (then the estimate is that time's cost too).
  for (const double vertical_speed : {0.0, 1.524}) {
    SCOPED_TRACE(testing::Message() << "vertical speed " << vertical_speed);
    expect_any_direction_optimal(vertical_speed);
  }
}

TEST(CuboidGraph, ASegmentCostsItsLengthOrItsTimeWithinBothLimits) {
  GlobalPlannerConfig config;
  const PlanRequest request = request_along_north({});
  CuboidGraph by_length(config, request);
  const Vec3 a(0, 0, -40), shallow(40, 0, -50), steep(10, 0, -70);
  EXPECT_DOUBLE_EQ(by_length.segment_cost(a, steep), (steep - a).norm());
  config.vertical_speed = config.speed / 2;
  CuboidGraph by_time(config, request);
  EXPECT_DOUBLE_EQ(by_time.segment_cost(a, shallow), (shallow - a).norm());  // 14 deg
  EXPECT_DOUBLE_EQ(by_time.segment_cost(a, steep), 2 * 30.0);                // 72 deg
  EXPECT_DOUBLE_EQ(by_time.segment_cost(steep, a), 2 * 30.0);                // down as up
}

void expect_any_direction_optimal(double vertical_speed) {
  GlobalPlannerConfig config;
  config.vertical_speed = vertical_speed;
  int compared = 0;
  for (unsigned seed = 1; seed <= 25; ++seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> north(5.0, 90.0), east(-40.0, 40.0), size(3.0, 20.0),
        height(10.0, 80.0);
    std::vector<ObstacleBox> boxes;
    for (int i = 0; i < 6 + static_cast<int>(seed % 5) * 3; ++i) {
      const Vec3 lo(north(rng), east(rng), -height(rng));
      boxes.push_back(cuboid(i + 1, lo, Vec3(lo.x() + size(rng), lo.y() + size(rng), 0.0)));
    }
    const PlanRequest request = request_along_north(boxes);
    CuboidGraph forward_graph(config, request);
    if (forward_graph.start_holder() >= 0 || forward_graph.goal_holder() >= 0) continue;
    CuboidGraph any_graph(config, request);
    CuboidGraph reference_graph(config, request);
    const std::vector<int> forward = search_forward(forward_graph);
    const std::vector<int> any = search_any_direction(any_graph);
    const double reference = dijkstra_any_direction(reference_graph);
    SCOPED_TRACE(testing::Message() << "seed " << seed);
    auto cost = [&](const std::vector<int>& sequence) {
      double c = 0.0;
      for (size_t k = 1; k < sequence.size(); ++k)
        c += any_graph.cost(sequence[k - 1], sequence[k]);
      return c;
    };
    if (reference == kInfinity) {
      EXPECT_TRUE(any.empty());
      EXPECT_TRUE(forward.empty());
      continue;
    }
    ASSERT_FALSE(any.empty());
    EXPECT_EQ(any.front(), 0);
    EXPECT_EQ(any.back(), 1);
    EXPECT_NEAR(cost(any), reference, 1e-6);
    CuboidGraph check(config, request);
    for (size_t k = 1; k < any.size(); ++k) EXPECT_FALSE(check.blocked(any[k - 1], any[k]));
    if (!forward.empty()) {
      EXPECT_LE(cost(any), cost(forward) + 1e-9);
    }
    // The lazy search tests no more segments than the full evaluation.
    EXPECT_LE(any_graph.segments_checked(), reference_graph.segments_checked());
    ++compared;
  }
  EXPECT_GE(compared, 15);
}

}  // namespace
}  // namespace ofn::planning
