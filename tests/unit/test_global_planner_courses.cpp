// The global planner on the benchmark courses (../shared/BENCHMARKS.md) with
// the true obstacles as cuboids: it takes the way round the course table
// names (over the walls, beside the tower and the cube, round the open ends
// of the wall baffle, through the gaps of the cube baffle, over the tree).
// With the paper's Eq. 10 on every segment the cube baffle and the tree
// have no such route; that strict model is checked last.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "ofn/common/frames.hpp"
#include "ofn/common/scenario.hpp"
#include "ofn/global_planner/global_planner.hpp"
#include "ofn/world/world.hpp"

namespace ofn::planning {
namespace {

constexpr double kFt = kMetresPerFoot;

Scenario load_course(const std::string& name) {
  const auto path = std::filesystem::path(OFN_SOURCE_DIR) / "sim" / "scenarios" / (name + ".yaml");
  return load_scenario(path.string());
}

// A yawed box as the mapper's blob detector would see it: pieces along its
// length, each by its axis-aligned bounds.
std::vector<ObstacleBox> split_along_length(const ObstacleSpec& spec, int pieces) {
  const Vec3 along_x(std::cos(spec.yaw), std::sin(spec.yaw), 0.0);
  const Vec3 along_y(-std::sin(spec.yaw), std::cos(spec.yaw), 0.0);
  const double piece = spec.width / pieces;
  const Vec3 half(std::abs(along_x.x()) * spec.length / 2 + std::abs(along_y.x()) * piece / 2,
                  std::abs(along_x.y()) * spec.length / 2 + std::abs(along_y.y()) * piece / 2, 0);
  std::vector<ObstacleBox> out;
  for (int k = 0; k < pieces; ++k) {
    const Vec3 centre =
        Vec3(spec.north, spec.east, 0) + along_y * (-spec.width / 2 + (k + 0.5) * piece);
    ObstacleBox b;
    b.id = spec.id * 100 + k;
    b.min_corner = centre - half;
    b.max_corner = centre + half;
    b.min_corner.z() = -spec.height;
    b.max_corner.z() = 0.0;
    out.push_back(b);
  }
  return out;
}

struct CourseRun {
  Scenario scenario;
  GlobalPlannerConfig config;
  PlanRequest request;
  PlanResult result;
  double highest = 0;  // m above ground
  double widest = 0;   // m, largest |y|
};

CourseRun plan_course(const std::string& name) {
  CourseRun run;
  run.scenario = load_course(name);
  const Scenario& s = run.scenario;
  PlanRequest request;
  for (const ObstacleSpec& spec : s.obstacles) {
    if (spec.kind == ObstacleSpec::Kind::kBox && std::abs(spec.yaw) > 1e-6) {
      for (const ObstacleBox& b : split_along_length(spec, 10)) request.obstacles.push_back(b);
      continue;
    }
    const world::Obstacle obstacle(spec, s.ground_altitude);
    ObstacleBox b;
    b.id = spec.id;
    b.min_corner = obstacle.bounds_min();
    b.max_corner = obstacle.bounds_max();
    request.obstacles.push_back(b);
  }
  request.start = s.start_position;
  request.start_velocity = s.start_velocity;
  request.leg_from = s.waypoints.front().position;
  request.goal = s.waypoints.back().position;

  run.config.clearance = s.limits.clearance;
  run.config.max_accel = s.limits.max_accel;
  run.config.speed = s.cruise_speed;
  run.config.ground_altitude = s.ground_altitude;
  GlobalPlanner planner(run.config);
  run.result = planner.plan(request);
  run.request = request;
  for (const Vec3& p : run.result.path) {
    run.highest = std::max(run.highest, -p.z() - s.ground_altitude);
    run.widest = std::max(run.widest, std::abs(p.y()));
  }
  std::printf("%-7s %-8s cost %6.1f ft, highest %5.1f ft, widest |y| %5.1f ft, %d nodes\n",
              name.c_str(), to_string(run.result.status), run.result.cost / kFt, run.highest / kFt,
              run.widest / kFt, run.result.nodes);
  return run;
}

// The path's y (m) where it crosses x = north (m); the path advances in x.
double y_at(const PlanResult& result, double north) {
  const auto& p = result.path;
  for (size_t k = 1; k < p.size(); ++k)
    if (p[k - 1].x() <= north && p[k].x() >= north) {
      const double t = (north - p[k - 1].x()) / std::max(1e-9, p[k].x() - p[k - 1].x());
      return p[k - 1].y() + t * (p[k].y() - p[k - 1].y());
    }
  ADD_FAILURE() << "the path never reaches x = " << north;
  return 0.0;
}

double altitude_of(const Vec3& p, const Scenario& s) {
  return -p.z() - s.ground_altitude;
}

TEST(GlobalPlannerCourses, Bench1ClimbsOverTheWall) {
  const CourseRun run = plan_course("bench1");
  ASSERT_EQ(run.result.status, PlanStatus::kOk);
  EXPECT_GE(run.highest, (140 + 20) * kFt - 0.1);
  EXPECT_LT(run.widest, 1.0);
}

TEST(GlobalPlannerCourses, Bench2GoesAroundTheTower) {
  const CourseRun run = plan_course("bench2");
  ASSERT_EQ(run.result.status, PlanStatus::kOk);
  const double start_altitude = altitude_of(run.scenario.start_position, run.scenario);
  EXPECT_LT(run.highest, start_altitude + 3.0);
  EXPECT_GE(std::abs(y_at(run.result, 200 * kFt)), (15 + 20) * kFt - 0.1);
}

TEST(GlobalPlannerCourses, Bench3ClimbsOverTheSlantedWall) {
  const CourseRun run = plan_course("bench3");
  ASSERT_EQ(run.result.status, PlanStatus::kOk);
  EXPECT_GE(run.highest, (140 + 20) * kFt - 0.1);
  EXPECT_LT(run.widest, 3.0);
}

TEST(GlobalPlannerCourses, Bench4GoesAroundTheCube) {
  const CourseRun run = plan_course("bench4");
  ASSERT_EQ(run.result.status, PlanStatus::kOk);
  const double start_altitude = altitude_of(run.scenario.start_position, run.scenario);
  EXPECT_LT(run.highest, start_altitude + 3.0);
  EXPECT_GE(std::abs(y_at(run.result, 200 * kFt)), (30 + 20) * kFt - 0.1);
}

TEST(GlobalPlannerCourses, Bench5PassesTheOpenEndOfEachWall) {
  const CourseRun run = plan_course("bench5");
  ASSERT_EQ(run.result.status, PlanStatus::kOk);
  const double start_altitude = altitude_of(run.scenario.start_position, run.scenario);
  EXPECT_LT(run.highest, start_altitude + 3.0);
  // First wall spans y -200..10 ft, the second -10..200 ft.
  EXPECT_GE(y_at(run.result, 120 * kFt), (10 + 20) * kFt - 0.1);
  EXPECT_LE(y_at(run.result, 320 * kFt), -(10 + 20) * kFt + 0.1);
}

TEST(GlobalPlannerCourses, Bench6ThreadsBothGaps) {
  const CourseRun run = plan_course("bench6");
  ASSERT_EQ(run.result.status, PlanStatus::kOk);
  const double start_altitude = altitude_of(run.scenario.start_position, run.scenario);
  EXPECT_LT(run.highest, start_altitude + 3.0);
  // First pair of boxes leaves y -30..30 ft free, the second y 10..70 ft;
  // each gap narrowed by the 20 ft clearance on both sides.
  EXPECT_LE(std::abs(y_at(run.result, 150 * kFt)), 10 * kFt + 0.1);
  const double y2 = y_at(run.result, 280 * kFt);
  EXPECT_GE(y2, 30 * kFt - 0.1);
  EXPECT_LE(y2, 50 * kFt + 0.1);
}

TEST(GlobalPlannerCourses, TreeIsClimbedOver) {
  const CourseRun run = plan_course("tree");
  ASSERT_EQ(run.result.status, PlanStatus::kOk);
  const world::Obstacle tree(run.scenario.obstacles.at(0), run.scenario.ground_altitude);
  const double tree_top = -tree.bounds_min().z() - run.scenario.ground_altitude;
  EXPECT_GE(run.highest, tree_top + run.scenario.limits.clearance - 0.1);
  EXPECT_LT(run.widest, 1.0);
}

// The paper's Eq. 10 with zero end slopes on every segment: the shift
// between bench6's gaps, from the first gap's exit corner (190, 10) ft to the
// second's entry corner (240, 30) ft, is 20 ft across in 50 ft:
// 6 * 20 * 10^2 / 50^2 = 4.8 ft/s^2 against 1.6, so the route goes outside
// the baffle; and the tree's descent from 100 ft to the goal's 60 ft within
// the 120.5 ft left needs 6 * 40 * 10^2 / 120.5^2 = 1.653 ft/s^2 against
// 1.65: no path at all.
TEST(GlobalPlannerCourses, StrictEq10OnEverySegmentRulesOutTheGapsAndTheTree) {
  CourseRun run = plan_course("bench6");
  run.config.accel_check_all_segments = true;
  const PlanResult strict = GlobalPlanner(run.config).plan(run.request);
  ASSERT_EQ(strict.status, PlanStatus::kOk);
  EXPECT_GE(std::abs(y_at(strict, 150 * kFt)), (70 + 20) * kFt - 0.1);
  const PlanGraph graph = GlobalPlanner(run.config).build_graph(run.request);
  const auto node_at = [&](double x_ft, double y_ft) {
    const Vec3 target = course_to_ned(Vec3(x_ft, y_ft, 120) * kFt);
    int best = 0;
    for (int i = 0; i < graph.size(); ++i)
      if ((graph.nodes[i] - target).norm() < (graph.nodes[best] - target).norm()) best = i;
    EXPECT_LT((graph.nodes[best] - target).norm(), 0.01) << "no node at " << x_ft << ", " << y_ft;
    return best;
  };
  EXPECT_EQ(graph.at(node_at(190, 10), node_at(240, 30)), PlanGraph::kBlocked);
  EXPECT_EQ(graph.at(node_at(190, -10), node_at(240, 30)), PlanGraph::kBlocked);

  CourseRun tree = plan_course("tree");
  tree.config.accel_check_all_segments = true;
  EXPECT_EQ(GlobalPlanner(tree.config).plan(tree.request).status, PlanStatus::kNoPath);
}

}  // namespace
}  // namespace ofn::planning
