// Ray casting cost of the simulated world and the LIDAR head: one beam
// against a bench3-like world (one box yawed 45 deg on the ground), against
// a tree, against a forest, and one whole scan (beams per second).

#include <benchmark/benchmark.h>

#include <vector>

#include "ofn/common/lidar_geometry.hpp"
#include "ofn/vehicle_sim/lidar_head.hpp"
#include "ofn/world/world.hpp"

namespace {

using ofn::ObstacleSpec;
using ofn::Quat;
using ofn::Vec3;

ObstacleSpec bench_box() {
  ObstacleSpec s;
  s.kind = ObstacleSpec::Kind::kBox;
  s.id = 1;
  // sim/scenarios/bench3.yaml: a 10 ft x 250 ft wall, 140 ft tall, 200 ft ahead.
  s.north = 61.0;
  s.length = 3.05;
  s.width = 76.2;
  s.height = 42.7;
  s.yaw = ofn::deg2rad(45);
  return s;
}

ObstacleSpec bench_tree(int id, double north, double east, int seed) {
  ObstacleSpec s;
  s.kind = ObstacleSpec::Kind::kTree;
  s.id = id;
  s.north = north;
  s.east = east;
  s.length = 10;
  s.width = 8;
  s.height = 15;
  s.seed = seed;
  return s;
}

/// The beam directions of one default scan from a level head.
std::vector<Vec3> scan_directions() {
  ofn::vehicle::LidarHead head(ofn::vehicle::LidarConfig{}, 0.0);
  const ofn::vehicle::LidarScan scan = head.scan(
      0, [](ofn::Utime) { return std::make_pair(Vec3(Vec3::Zero()), Quat::Identity()); },
      ofn::world::World());
  std::vector<Vec3> out;
  for (const auto& b : scan.beams)
    out.push_back(ofn::beam_direction_sensor(b.elevation, b.layer_angle));
  return out;
}

void cast_all(benchmark::State& state, const ofn::world::World& world,
              const std::vector<Vec3>& directions, const Vec3& origin) {
  size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(world.ray_cast(origin, directions[i], 61.0));
    if (++i == directions.size()) i = 0;
  }
  state.SetItemsProcessed(state.iterations());
}

void BM_RayCastBench3World(benchmark::State& state) {
  const ofn::world::World world({bench_box()}, 0.0);
  cast_all(state, world, scan_directions(), Vec3(20, 0, -36.6));
}
BENCHMARK(BM_RayCastBench3World);

void BM_RayCastTree(benchmark::State& state) {
  const ofn::world::World world({bench_tree(1, 25, 0, 3)}, 0.0);
  cast_all(state, world, scan_directions(), Vec3(0, 0, -10));
}
BENCHMARK(BM_RayCastTree);

void BM_RayCastForest(benchmark::State& state) {
  std::vector<ObstacleSpec> trees;
  for (int i = 0; i < 10; ++i)
    for (int j = 0; j < 10; ++j)
      trees.push_back(bench_tree(10 * i + j + 1, 15.0 * i + 10, 15.0 * j - 70, i * 10 + j));
  const ofn::world::World world(trees, 0.0);
  cast_all(state, world, scan_directions(), Vec3(0, 0, -10));
}
BENCHMARK(BM_RayCastForest);

void BM_TreeConstruction(benchmark::State& state) {
  int seed = 0;
  for (auto _ : state) benchmark::DoNotOptimize(ofn::world::Obstacle(bench_tree(1, 0, 0, seed++)));
}
BENCHMARK(BM_TreeConstruction)->Unit(benchmark::kMicrosecond);

void BM_LidarScanBench3World(benchmark::State& state) {
  const ofn::world::World world({bench_box()}, 0.0);
  ofn::vehicle::LidarHead head(ofn::vehicle::LidarConfig{}, 61.0);
  const auto pose_at = [](ofn::Utime t) {
    return std::make_pair(Vec3(20 + 3.0 * t * 1e-6, 0, -36.6), Quat::Identity());
  };
  for (auto _ : state) benchmark::DoNotOptimize(head.scan(0, pose_at, world));
  state.SetItemsProcessed(state.iterations() * head.beams_per_scan());
}
BENCHMARK(BM_LidarScanBench3World)->Unit(benchmark::kMicrosecond);

}  // namespace
