// Cost of one receding-horizon solve over a recorded-style flight: the
// vehicle follows each solution kinematically for 0.1 s while approaching
// and passing bench1's wall (over) and bench4's cube (around), against the
// rasterised true obstacles. The same problems are then solved cold (from
// the hand-made route), warm (from the recorded previous solution) and warm
// with MMA instead of SLSQP. Counters: median and 99th-percentile solve
// time (ms), mean objective evaluations, share of feasible solves.

#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "ofn/common/scenario.hpp"
#include "ofn/map/distance_field.hpp"
#include "ofn/rh_optimizer/rh_optimizer.hpp"
#include "ofn/rh_optimizer/rh_planner.hpp"
#include "ofn/world/world.hpp"

namespace {

using ofn::BsplineTrajectory;
using ofn::Vec3;
using namespace ofn::rh;

constexpr double kStep = 0.1;          // s the vehicle follows each solution
constexpr double kMapperMargin = 1.5;  // m, horizontal inflation like the mapper's grid

ofn::mapping::Heightfield rasterise(const ofn::Scenario& scenario) {
  ofn::mapping::Heightfield field;
  field.origin_north = -45;
  field.origin_east = -85;
  field.rows = 185;
  field.cols = 170;
  field.top.assign(static_cast<size_t>(field.rows) * field.cols, 0.0f);
  for (const ofn::ObstacleSpec& spec : scenario.obstacles) {
    const ofn::world::Obstacle obstacle(spec, scenario.ground_altitude);
    for (int r = 0; r < field.rows; ++r)
      for (int c = 0; c < field.cols; ++c) {
        const Vec3 p(field.cell_centre_north(r), field.cell_centre_east(c),
                     -(scenario.ground_altitude + 0.5 * spec.height));
        if (obstacle.distance(p) <= kMapperMargin)
          field.at(r, c) = std::max(field.at(r, c), static_cast<float>(spec.height));
      }
  }
  return field;
}

struct RecordedProblem {
  RhProblem problem;
  std::vector<Vec3> route;     // world NED, the cold guess
  BsplineTrajectory previous;  // the solution flown into this problem
  double elapsed = 0;          // s since that solution's start
};

Vec3 feet(double x, double y, double h) {
  return ofn::course_to_ned(Vec3(x, y, h) * ofn::kMetresPerFoot);
}

void record_course(const std::string& name, const std::vector<Vec3>& route_feet,
                   std::vector<RecordedProblem>& out) {
  const ofn::Scenario scenario =
      ofn::load_scenario(std::string(OFN_SOURCE_DIR) + "/sim/scenarios/" + name + ".yaml");
  auto field = std::make_shared<ofn::mapping::DistanceField>();
  field->build(rasterise(scenario), 0.0, 80.0);
  std::vector<Vec3> route;
  for (const Vec3& p : route_feet) route.push_back(feet(p.x(), p.y(), p.z()));
  double far_north = -1e9;
  for (const ofn::ObstacleSpec& spec : scenario.obstacles)
    far_north = std::max(far_north, ofn::world::Obstacle(spec).bounds_max().x());

  RhProblem problem;
  problem.frame = ofn::GuidanceFrame::from_leg(scenario.waypoints.front().position,
                                               scenario.waypoints.back().position);
  problem.target = scenario.waypoints.back().position;
  problem.limits = scenario.limits;
  problem.clearance = [field](const Vec3& ned) { return field->query(ned); };
  problem.position = feet(0, 0, 120);
  problem.velocity = Vec3(scenario.cruise_speed, 0, 0);
  const double far_x = problem.frame.to_guidance(Vec3(far_north, 0, 0)).x();

  RhOptimizer optimizer;
  BsplineTrajectory flown;
  double flown_elapsed = 0;
  int failures = 0;
  for (int step = 0; step < 600 && problem.position.x() < feet(300, 0, 0).x(); ++step) {
    // Eq. 6: the horizon ends past the farthest obstacle, or at the sensor's
    // range once the obstacles are (nearly) behind.
    const double x0 = problem.frame.to_guidance(problem.position).x();
    const double past_obstacles = far_x + scenario.limits.clearance;
    problem.terminal_x = past_obstacles > x0 + 0.5 * scenario.limits.sensor_range
                             ? std::min(x0 + scenario.limits.sensor_range, past_obstacles)
                             : x0 + scenario.limits.sensor_range;
    const InitialGuess guess =
        flown.empty() ? RhOptimizer::guess_from_path(route, problem, scenario.cruise_speed)
                      : RhOptimizer::guess_from_previous(flown, flown_elapsed, problem);
    if (!flown.empty()) out.push_back({problem, route, flown, flown_elapsed});
    SolveReport report = optimizer.solve(problem, guess);
    if (!report.feasible && guess.warm)
      report = optimizer.solve(problem,
                               RhOptimizer::guess_from_path(route, problem, scenario.cruise_speed));
    if (report.feasible) {
      flown = report.trajectory;
      flown_elapsed = 0;
    } else {
      ++failures;
    }
    if (flown.empty()) break;
    flown_elapsed += kStep;
    problem.position = flown.position(flown_elapsed);
    problem.velocity = flown.velocity(flown_elapsed);
    problem.acceleration = flown.acceleration(flown_elapsed);
  }
  if (failures > 0)
    std::fprintf(stderr, "%s: %d of the recorded solves failed (the older solution was flown on)\n",
                 name.c_str(), failures);
}

const std::vector<RecordedProblem>& recorded_flight() {
  static const std::vector<RecordedProblem> problems = [] {
    std::vector<RecordedProblem> all;
    record_course("bench1",
                  {{-100, 0, 120}, {20, 0, 120}, {150, 0, 180}, {260, 0, 180}, {500, 0, 120}}, all);
    record_course("bench4",
                  {{-100, 0, 120},
                   {40, 0, 120},
                   {150, 75, 120},
                   {250, 75, 120},
                   {360, 0, 120},
                   {500, 0, 120}},
                  all);
    return all;
  }();
  return problems;
}

enum class Start { kCold, kWarm };

// stride: solve every stride-th problem of the sequence (MMA is slow enough
// that the whole sequence would dominate the run).
void run_sequence(benchmark::State& state, Start start, RhAlgorithm algorithm, size_t stride = 1,
                  double screening_margin = 0.0) {
  const std::vector<RecordedProblem>& all = recorded_flight();
  std::vector<RecordedProblem> problems;
  for (size_t i = 0; i < all.size(); i += stride) problems.push_back(all[i]);
  RhSettings settings;
  settings.algorithm = algorithm;
  settings.screening_margin = screening_margin;
  RhOptimizer optimizer(settings);
  std::vector<double> times;
  long evaluations = 0, feasible = 0;
  double cost_sum = 0;
  for (auto _ : state) {
    for (const RecordedProblem& recorded : problems) {
      const InitialGuess guess =
          start == Start::kWarm ? RhOptimizer::guess_from_previous(
                                      recorded.previous, recorded.elapsed, recorded.problem)
                                : RhOptimizer::guess_from_path(recorded.route, recorded.problem,
                                                               recorded.problem.limits.max_speed);
      const auto begin = std::chrono::steady_clock::now();
      const SolveReport report = optimizer.solve(recorded.problem, guess);
      times.push_back(
          std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count());
      evaluations += report.iterations;
      feasible += report.feasible ? 1 : 0;
      if (report.feasible) cost_sum += report.cost;
    }
  }
  std::sort(times.begin(), times.end());
  const auto at = [&](double q) {
    return times[std::min(times.size() - 1, static_cast<size_t>(q * (times.size() - 1) + 0.5))];
  };
  const double solves = static_cast<double>(times.size());
  state.counters["problems"] = static_cast<double>(problems.size());
  state.counters["median_ms"] = 1e3 * at(0.5);
  state.counters["p99_ms"] = 1e3 * at(0.99);
  state.counters["max_ms"] = 1e3 * times.back();
  state.counters["mean_evaluations"] = static_cast<double>(evaluations) / solves;
  state.counters["feasible_share"] = static_cast<double>(feasible) / solves;
  state.counters["mean_feasible_cost"] =
      feasible > 0 ? cost_sum / static_cast<double>(feasible) : 0;
}

void BM_RhSolveCold(benchmark::State& state) {
  run_sequence(state, Start::kCold, RhAlgorithm::kSlsqp);
}
void BM_RhSolveWarm(benchmark::State& state) {
  run_sequence(state, Start::kWarm, RhAlgorithm::kSlsqp);
}
void BM_RhSolveWarmMma(benchmark::State& state) {
  run_sequence(state, Start::kWarm, RhAlgorithm::kMma, 4);
}
void BM_RhSolveWarmScreened(benchmark::State& state) {
  run_sequence(state, Start::kWarm, RhAlgorithm::kSlsqp, 1, state.range(0) / 100.0);
}
BENCHMARK(BM_RhSolveCold)->Iterations(1)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_RhSolveWarmScreened)
    ->Arg(25)
    ->Arg(50)
    ->Arg(100)
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_RhSolveWarm)->Iterations(1)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_RhSolveWarmMma)->Iterations(1)->Unit(benchmark::kMillisecond);

// A stop on the last waypoint in open space: from cruise speed 42 m short of
// it, the planner steps every 0.1 s from where its own last plan has the
// vehicle (as the service does) until the vehicle is at rest. With the
// service's settings the first plan brakes on the acceleration reserve, and
// most warm solves of the last three seconds find no feasible point (the
// commanded-acceleration row, a + tau da/dt): the previous plan is kept and
// flown, as it should be, but the solve's time is spent for nothing, and an
// escape leg from a hover, which has no previous plan, has been seen to stop
// there (docs/LIMITATIONS.md). Counters: steps, steps that kept the previous
// plan, median and worst step time.
void BM_RhStopAtTheLastWaypoint(benchmark::State& state) {
  RhSettings settings;  // the service's (config/rh_optimizer.yaml)
  settings.weights = Vec3(30.0, 30.0, 30.0);
  settings.speed_margin = 0.005;
  settings.accel_margin = 0.06;
  settings.forward_speed_reserve = 0.15;
  settings.clearance_margin = 0.5;
  ofn::Limits limits;  // the benchmarks' (ft and ft/s^2 in SI)
  limits.max_speed = 3.048;
  limits.max_accel = 0.48768;
  limits.max_vertical_speed = 1.524;
  limits.min_forward_speed = 0.0;
  limits.clearance = 6.096;
  limits.sensor_range = 60.96;
  const Vec3 leg_from(0, 0, -36.6), target(152.4, 0, -36.6);
  int steps = 0, kept = 0;
  std::vector<double> times;
  for (auto _ : state) {
    RhPlanner planner(settings);
    Vec3 p(110.0, 0, -36.6), v(3.033, 0, 0), a = Vec3::Zero();
    BsplineTrajectory flown;
    double t = 0, flown_start = 0;
    for (int k = 0; k < 600; ++k, t += kStep) {
      StepInput in;
      in.time = t;
      RhProblem& problem = in.problem;
      problem.frame = ofn::GuidanceFrame::from_leg(leg_from, target);
      problem.position = p;
      problem.velocity = v;
      problem.acceleration = a;
      problem.target = target;
      problem.terminal_x = problem.frame.to_guidance(target).x();
      problem.stop_at_target = true;
      problem.limits = limits;
      in.global_path = {p, target};
      in.global_path_changed = k == 0;
      const auto begin = std::chrono::steady_clock::now();
      const StepOutput out = planner.step(in);
      times.push_back(
          std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count());
      ++steps;
      if (out.mode == StepMode::kKeptPrevious) ++kept;
      if (out.mode != StepMode::kKeptPrevious) {
        flown = out.trajectory;
        flown_start = out.start_time;
      }
      const double since = t + kStep - flown_start;
      if (flown.empty() || since > flown.duration()) break;
      p = flown.position(since);
      v = flown.velocity(since);
      a = flown.acceleration(since);
      if (v.norm() < 0.01 && (p - target).norm() < 0.05) break;
    }
  }
  std::sort(times.begin(), times.end());
  state.counters["steps"] = steps;
  state.counters["kept_previous"] = kept;
  state.counters["median_ms"] = times.empty() ? 0 : 1e3 * times[times.size() / 2];
  state.counters["max_ms"] = times.empty() ? 0 : 1e3 * times.back();
}
BENCHMARK(BM_RhStopAtTheLastWaypoint)->Iterations(1)->Unit(benchmark::kMillisecond);

}  // namespace
