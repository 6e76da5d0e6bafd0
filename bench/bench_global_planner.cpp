// Global planner cost on seeded random cuboid fields of 10, 50 and 200
// boxes over a 400 ft x 200 ft course (the benchmarks' start and goal), and
// OMPL's RRT* as a yardstick: the same fields, the same clearance, given
// the wall time our planner takes on that field. RRT* knows nothing of the
// Eq. 10 acceleration limit, so its paths are shorter than any our planner
// may return whenever the limit binds.

#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <map>
#include <memory>
#include <random>
#include <vector>

#include <ompl/base/objectives/PathLengthOptimizationObjective.h>
#include <ompl/base/spaces/RealVectorStateSpace.h>
#include <ompl/geometric/SimpleSetup.h>
#include <ompl/geometric/planners/rrt/RRTstar.h>
#include <ompl/util/Console.h>

#include "ofn/common/frames.hpp"
#include "ofn/global_planner/global_planner.hpp"

namespace {

using ofn::Vec3;
using ofn::planning::GlobalPlanner;
using ofn::planning::GlobalPlannerConfig;
using ofn::planning::ObstacleBox;
using ofn::planning::PlanRequest;
using ofn::planning::PlanResult;
using ofn::planning::PlanStatus;

constexpr double kFt = ofn::kMetresPerFoot;
constexpr int kFieldsPerSize = 8;

PlanRequest random_field(int boxes, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> north(0.0, 400.0 * kFt), east(-100.0 * kFt, 100.0 * kFt),
      size(10.0 * kFt, 60.0 * kFt), height(60.0 * kFt, 300.0 * kFt), coin(0.0, 1.0);
  PlanRequest r;
  r.start = ofn::course_to_ned(Vec3(-100, 0, 120) * kFt);
  r.leg_from = r.start;
  r.start_velocity = Vec3(10 * kFt, 0, 0);
  r.goal = ofn::course_to_ned(Vec3(500, 0, 120) * kFt);
  for (int i = 0; i < boxes; ++i) {
    const double n = north(rng), e = east(rng), l = size(rng), w = size(rng);
    ObstacleBox b;
    b.id = i + 1;
    b.min_corner = Vec3(n - l / 2, e - w / 2, -height(rng));
    b.max_corner = Vec3(n + l / 2, e + w / 2, 0.0);
    b.top_observed = coin(rng) > 0.2;
    r.obstacles.push_back(b);
  }
  return r;
}

const std::vector<PlanRequest>& fields(int boxes) {
  static std::map<int, std::vector<PlanRequest>> cache;
  auto& list = cache[boxes];
  if (list.empty())
    for (int k = 0; k < kFieldsPerSize; ++k)
      list.push_back(random_field(boxes, 1000u * static_cast<unsigned>(boxes) + k));
  return list;
}

// Mean plan() wall time per field (s), the RRT* budget on that field.
const std::vector<double>& planner_times(int boxes) {
  static std::map<int, std::vector<double>> cache;
  auto& times = cache[boxes];
  if (times.empty()) {
    GlobalPlanner planner;
    for (const PlanRequest& r : fields(boxes)) {
      constexpr int kRepeats = 20;
      const auto t0 = std::chrono::steady_clock::now();
      for (int i = 0; i < kRepeats; ++i) benchmark::DoNotOptimize(planner.plan(r));
      const std::chrono::duration<double> dt = std::chrono::steady_clock::now() - t0;
      times.push_back(dt.count() / kRepeats);
    }
  }
  return times;
}

void plan_fields(benchmark::State& state, const GlobalPlannerConfig& config) {
  const auto& list = fields(static_cast<int>(state.range(0)));
  GlobalPlanner planner(config);
  size_t k = 0;
  double nodes = 0, length = 0, plans = 0, ok = 0;
  for (auto _ : state) {
    const PlanResult result = planner.plan(list[k]);
    k = (k + 1) % list.size();
    plans += 1;
    nodes += result.nodes;
    if (result.status == PlanStatus::kOk) {
      ok += 1;
      length += result.cost;
    }
  }
  state.counters["nodes"] = nodes / std::max(1.0, plans);
  state.counters["path_m"] = length / std::max(1.0, ok);
  state.counters["ok_share"] = ok / std::max(1.0, plans);
}

void BM_GlobalPlan(benchmark::State& state) {
  plan_fields(state, GlobalPlannerConfig{});
}
BENCHMARK(BM_GlobalPlan)->Arg(10)->Arg(50)->Arg(200)->Unit(benchmark::kMicrosecond);

// The Eq. 10 limit makes most dense fields unsolvable (no_path is found
// quickly); without it every field has a path and the search does its
// full work, the cost that matters for the speed target.
void BM_GlobalPlanNoAccelLimit(benchmark::State& state) {
  GlobalPlannerConfig config;
  config.max_accel = 1e6;
  plan_fields(state, config);
}
BENCHMARK(BM_GlobalPlanNoAccelLimit)->Arg(10)->Arg(50)->Arg(200)->Unit(benchmark::kMicrosecond);

namespace ob = ompl::base;
namespace og = ompl::geometric;

bool outside_every_clearance_box(const PlanRequest& r, double clearance, const Vec3& p) {
  for (const ObstacleBox& b : r.obstacles) {
    const Vec3 lo = b.min_corner - Vec3::Constant(clearance);
    const Vec3 hi = b.max_corner + Vec3::Constant(clearance);
    if ((p.array() > lo.array()).all() && (p.array() < hi.array()).all()) return false;
  }
  return true;
}

void BM_RrtStar(benchmark::State& state) {
  ompl::msg::setLogLevel(ompl::msg::LOG_NONE);
  const int boxes = static_cast<int>(state.range(0));
  const auto& list = fields(boxes);
  const auto& budgets = planner_times(boxes);
  const double clearance = GlobalPlannerConfig{}.clearance;
  size_t k = 0;
  double runs = 0, solved = 0, length = 0;
  for (auto _ : state) {
    const PlanRequest& r = list[k];
    const double budget = std::max(1e-3, budgets[k]);
    k = (k + 1) % list.size();

    auto space = std::make_shared<ob::RealVectorStateSpace>(3);
    ob::RealVectorBounds bounds(3);
    bounds.setLow(0, r.start.x() - 10);
    bounds.setHigh(0, r.goal.x() + 10);
    bounds.setLow(1, -150 * kFt);
    bounds.setHigh(1, 150 * kFt);
    bounds.setLow(2, -400 * kFt);
    bounds.setHigh(2, -20 * kFt);
    space->setBounds(bounds);
    og::SimpleSetup setup(space);
    setup.setStateValidityChecker([&r, clearance](const ob::State* s) {
      const auto* v = s->as<ob::RealVectorStateSpace::StateType>();
      return outside_every_clearance_box(r, clearance,
                                         Vec3(v->values[0], v->values[1], v->values[2]));
    });
    // About 1 m between checked states along a motion.
    setup.getSpaceInformation()->setStateValidityCheckingResolution(0.005);
    ob::ScopedState<> start(space), goal(space);
    for (int i = 0; i < 3; ++i) {
      start[i] = r.start[i];
      goal[i] = r.goal[i];
    }
    setup.setStartAndGoalStates(start, goal);
    setup.setOptimizationObjective(
        std::make_shared<ob::PathLengthOptimizationObjective>(setup.getSpaceInformation()));
    setup.setPlanner(std::make_shared<og::RRTstar>(setup.getSpaceInformation()));
    const ob::PlannerStatus status = setup.solve(budget);
    runs += 1;
    if (status == ob::PlannerStatus::EXACT_SOLUTION) {
      solved += 1;
      length += setup.getSolutionPath().length();
    }
  }
  state.counters["path_m"] = length / std::max(1.0, solved);
  state.counters["success_share"] = solved / std::max(1.0, runs);
}
BENCHMARK(BM_RrtStar)->Arg(10)->Arg(50)->Arg(200)->Unit(benchmark::kMillisecond)->MinTime(0.3);

}  // namespace
