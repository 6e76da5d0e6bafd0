// Costs of the mapper's per-scan map updates: hits into the 2.5-D obstacle
// grid, the grid's margin-and-smoothing pass, one scan into the 3-D
// occupancy map, and the column query the mapper runs per occupied cell.

#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include "ofn/mapper/obstacle_grid.hpp"
#include "ofn/mapper/occupancy_map.hpp"

namespace {

using ofn::Vec3;
using ofn::mapping::ObstacleGrid;
using ofn::mapping::ObstacleGridConfig;
using ofn::mapping::OccupancyMap;
using ofn::mapping::OccupancyMapConfig;

constexpr double kSensorAltitude = 20.0;
constexpr double kWallNorth = 40.0;
constexpr double kWallTop = 30.0;
constexpr double kMaxRange = 61.0;

struct Scan {
  Vec3 origin;
  std::vector<Vec3> hits;
  std::vector<Vec3> free_ray_ends;
};

// 1360 beams (40 azimuths over 60 deg x 34 elevations over 34 deg) from a
// sensor at 20 m altitude facing a 30 m tall wall 40 m north; beams that
// miss it reach the ground or max range.
Scan wall_scan() {
  Scan scan;
  scan.origin = Vec3(0, 0, -kSensorAltitude);
  for (int a = 0; a < 40; ++a) {
    const double az = ofn::deg2rad(-30.0 + 60.0 * a / 39.0);
    for (int e = 0; e < 34; ++e) {
      const double el = ofn::deg2rad(-27.0 + 34.0 * e / 33.0);
      const Vec3 dir(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), -std::sin(el));
      double range = kMaxRange;
      bool hit = false;
      const double to_wall = kWallNorth / dir.x();
      const double wall_alt = kSensorAltitude - to_wall * dir.z();
      if (to_wall < range && wall_alt >= 0 && wall_alt <= kWallTop) {
        range = to_wall;
        hit = true;
      }
      if (dir.z() > 0 && kSensorAltitude / dir.z() < range) {
        range = kSensorAltitude / dir.z();
        hit = true;
      }
      (hit ? scan.hits : scan.free_ray_ends).push_back(scan.origin + range * dir);
    }
  }
  return scan;
}

std::vector<Vec3> all_beam_ends(const Scan& scan) {
  std::vector<Vec3> ends = scan.hits;
  ends.insert(ends.end(), scan.free_ray_ends.begin(), scan.free_ray_ends.end());
  return ends;
}

void BM_GridInsertHits(benchmark::State& state) {
  ObstacleGrid grid{ObstacleGridConfig{}};
  const std::vector<Vec3> points = all_beam_ends(wall_scan());
  for (auto _ : state) benchmark::DoNotOptimize(grid.insert_hits(points));
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(points.size()));
}
BENCHMARK(BM_GridInsertHits)->Unit(benchmark::kMicrosecond);

// The filtered layer recomputed after each scan (every scan makes it dirty:
// here a hit alternates between two heights in one cell). Arg 0: the wall
// scan's hits; arg 1: the worst case, a pole in every 5th cell both ways
// across the whole 140 x 140 grid.
void BM_GridFilteredAfterScan(benchmark::State& state) {
  ObstacleGrid grid{ObstacleGridConfig{}};
  grid.insert_hits(wall_scan().hits);
  if (state.range(0)) {
    std::vector<Vec3> poles;
    for (double n = -69.5; n < 70.0; n += 5.0)
      for (double e = -69.5; e < 70.0; e += 5.0) poles.emplace_back(n, e, -12.0);
    grid.insert_hits(poles);
  }
  const int row = grid.raw().row_of(kWallNorth), col = grid.raw().col_of(0.0);
  float toggle = 0.0f;
  for (auto _ : state) {
    state.PauseTiming();
    grid.lower_cell(row, col, 0.0f);
    grid.insert_hits({Vec3(kWallNorth + 0.5, 0.5, -(kWallTop - toggle))});
    toggle = 1.0f - toggle;
    state.ResumeTiming();
    benchmark::DoNotOptimize(grid.filtered().top.data());
  }
}
BENCHMARK(BM_GridFilteredAfterScan)
    ->Arg(0)
    ->Arg(1)
    ->ArgNames({"whole_grid"})
    ->Unit(benchmark::kMicrosecond);

void BM_OccupancyInsertScan(benchmark::State& state) {
  OccupancyMapConfig config;
  config.resolution = 1.0;
  config.max_range = kMaxRange;
  OccupancyMap map(config);
  const Scan scan = wall_scan();
  for (auto _ : state) map.insert_scan(scan.origin, scan.hits, scan.free_ray_ends);
  state.SetItemsProcessed(state.iterations() *
                          static_cast<int64_t>(scan.hits.size() + scan.free_ray_ends.size()));
  state.counters["nodes"] = static_cast<double>(map.num_nodes());
  state.counters["kB"] = static_cast<double>(map.memory_bytes()) / 1024.0;
}
BENCHMARK(BM_OccupancyInsertScan)->Unit(benchmark::kMillisecond);

// One grid cell's query as the mapper makes it: a 1 m column searched from
// above the wall top down to the ground clearance, over the wall (found
// near the top) and over open ground (searched to the bottom).
void BM_OccupancyColumnTop(benchmark::State& state) {
  OccupancyMap map(OccupancyMapConfig{});
  const Scan scan = wall_scan();
  for (int i = 0; i < 3; ++i) map.insert_scan(scan.origin, scan.hits, scan.free_ray_ends);
  const double north = state.range(0) ? kWallNorth + 0.5 : 20.5;
  for (auto _ : state) benchmark::DoNotOptimize(map.column_top(north, 0.5, 0.5, 1.0, 40.0));
}
BENCHMARK(BM_OccupancyColumnTop)->Arg(1)->Arg(0)->ArgNames({"over_wall"});

void BM_OccupancyForgetFar(benchmark::State& state) {
  OccupancyMap map(OccupancyMapConfig{});
  const Scan scan = wall_scan();
  map.insert_scan(scan.origin, scan.hits, scan.free_ray_ends);
  // Nothing is far: the cost of the 1 Hz sweep over the whole tree.
  for (auto _ : state) map.forget_far(0.0, 0.0);
}
BENCHMARK(BM_OccupancyForgetFar)->Unit(benchmark::kMicrosecond);

}  // namespace
