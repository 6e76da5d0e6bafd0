// Per-cycle costs of the global planner's obstacle input: blob detection into
// cuboids on a vehicle-sized grid, and one obstacle-database update.

#include <benchmark/benchmark.h>

#include <vector>

#include "ofn/mapper/cuboid_extractor.hpp"
#include "ofn/mapper/obstacle_database.hpp"

namespace {

using ofn::mapping::Cuboid;
using ofn::mapping::CuboidExtractor;
using ofn::mapping::CuboidExtractorConfig;
using ofn::mapping::Heightfield;
using ofn::mapping::ObstacleDatabase;
using ofn::mapping::ObstacleDatabaseConfig;

/// 140 x 140 cells of 1 m: a 2-cell thick wall slanted at 45 degrees and a
/// few boxes of different heights.
Heightfield course_grid() {
  Heightfield grid;
  grid.origin_north = -70;
  grid.origin_east = -70;
  grid.rows = 140;
  grid.cols = 140;
  grid.top.assign(static_cast<size_t>(grid.rows) * grid.cols, 0.0f);
  for (int i = 10; i < 110; ++i) grid.at(i, i) = grid.at(i, i + 1) = 30.0f;
  const auto box = [&](int row0, int col0, int size, float top) {
    for (int row = row0; row < row0 + size; ++row)
      for (int col = col0; col < col0 + size; ++col) grid.at(row, col) = top;
  };
  box(20, 90, 12, 25.0f);
  box(100, 20, 8, 40.0f);
  box(60, 10, 15, 18.0f);
  box(120, 120, 6, 12.0f);
  return grid;
}

void BM_CuboidExtract(benchmark::State& state) {
  const CuboidExtractor extractor{CuboidExtractorConfig{}};
  const Heightfield grid = course_grid();
  for (auto _ : state) benchmark::DoNotOptimize(extractor.extract(grid));
}
BENCHMARK(BM_CuboidExtract)->Unit(benchmark::kMicrosecond);

void BM_ObstacleDatabaseUpdate(benchmark::State& state) {
  std::vector<Cuboid> cuboids;
  for (int i = 0; i < 50; ++i) {
    Cuboid c;
    const double north = (i / 10) * 20.0, east = (i % 10) * 20.0;
    c.min = ofn::Vec3(north, east, -20.0 - i);
    c.max = ofn::Vec3(north + 8.0, east + 8.0, 0);
    cuboids.push_back(c);
  }
  ObstacleDatabase db{ObstacleDatabaseConfig{}};
  const auto in_view = [](const Cuboid&) { return true; };
  db.update(cuboids, 0, in_view);
  ofn::Utime now = 0;
  for (auto _ : state) {
    now += ofn::kMicrosPerSecond;
    db.update(cuboids, now, in_view);
    benchmark::DoNotOptimize(db.entries().data());
  }
}
BENCHMARK(BM_ObstacleDatabaseUpdate)->Unit(benchmark::kMicrosecond);

}  // namespace
