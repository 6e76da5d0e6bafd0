// Cost of the obstacle distance field: one build over the default mapper grid
// (140 x 140 cells at 1 m, 60 altitude slices) with a wall and boxes, and a
// point query with and without the gradient, as the optimiser calls it.

#include <benchmark/benchmark.h>

#include <algorithm>
#include <array>
#include <random>
#include <vector>

#include "ofn/map/distance_field.hpp"

namespace {

using ofn::Vec3;
using ofn::mapping::DistanceField;
using ofn::mapping::Heightfield;

Heightfield wall_and_boxes() {
  Heightfield field;
  field.rows = 140;
  field.cols = 140;
  field.resolution = 1.0;
  field.origin_north = -70;
  field.origin_east = -70;
  field.top.assign(140 * 140, 0.0f);
  const auto box = [&](int row0, int col0, int rows, int cols, float top) {
    for (int r = row0; r < std::min(140, row0 + rows); ++r)
      for (int c = col0; c < std::min(140, col0 + cols); ++c) field.at(r, c) = top;
  };
  box(20, 90, 100, 3, 45.0f);  // a wall across most of the grid
  std::mt19937 rng(1);
  std::uniform_int_distribution<int> position(0, 130), size(3, 15);
  std::uniform_real_distribution<float> height(5.0f, 70.0f);
  for (int b = 0; b < 12; ++b) box(position(rng), position(rng), size(rng), size(rng), height(rng));
  return field;
}

std::vector<Vec3> query_points(int count) {
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> horizontal(-75, 75), altitude(-2, 62);
  std::vector<Vec3> points;
  for (int i = 0; i < count; ++i)
    points.emplace_back(horizontal(rng), horizontal(rng), -altitude(rng));
  return points;
}

// Where trajectories within a few metres of one altitude query the field.
std::vector<Vec3> points_near_one_altitude() {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> horizontal(-75, 75), altitude(27, 33);
  std::vector<Vec3> points;
  for (int i = 0; i < 1024; ++i)
    points.emplace_back(horizontal(rng), horizontal(rng), -altitude(rng));
  return points;
}

// Two fields one cell apart, built in turn: a build on the input of the
// last one keeps its slices, so the same field twice would measure nothing.
std::array<Heightfield, 2> alternating_fields() {
  std::array<Heightfield, 2> fields{wall_and_boxes(), wall_and_boxes()};
  fields[1].top[0] = 3.0f;
  return fields;
}

void BM_DistanceFieldBuild(benchmark::State& state) {
  const std::array<Heightfield, 2> fields = alternating_fields();
  DistanceField distance_field;
  size_t n = 0;
  for (auto _ : state) {
    distance_field.build(fields[n++ % 2], 0, 59);
    distance_field.build_all_slices();
    benchmark::ClobberMemory();
  }
}
BENCHMARK(BM_DistanceFieldBuild)->Unit(benchmark::kMillisecond);

// What the RH optimiser does after a map message: a new field, queried by
// trajectories within a few metres of one altitude, so only the slices
// there are transformed.
void BM_DistanceFieldBuildAndQueryNearOneAltitude(benchmark::State& state) {
  const std::array<Heightfield, 2> fields = alternating_fields();
  const std::vector<Vec3> points = points_near_one_altitude();
  DistanceField distance_field;
  size_t n = 0;
  for (auto _ : state) {
    distance_field.build(fields[n++ % 2], 0, 59);
    for (const Vec3& p : points) benchmark::DoNotOptimize(distance_field.query(p));
  }
}
BENCHMARK(BM_DistanceFieldBuildAndQueryNearOneAltitude)->Unit(benchmark::kMillisecond);

// The same after a map message that changed nothing the field sees (a
// hover over mapped ground): the slices transformed stay.
void BM_DistanceFieldRebuildSameInputAndQuery(benchmark::State& state) {
  const Heightfield field = wall_and_boxes();
  const std::vector<Vec3> points = points_near_one_altitude();
  DistanceField distance_field;
  for (auto _ : state) {
    distance_field.build(field, 0, 59);
    for (const Vec3& p : points) benchmark::DoNotOptimize(distance_field.query(p));
  }
}
BENCHMARK(BM_DistanceFieldRebuildSameInputAndQuery)->Unit(benchmark::kMillisecond);

void BM_DistanceFieldQuery(benchmark::State& state) {
  DistanceField distance_field;
  distance_field.build(wall_and_boxes(), 0, 59);
  distance_field.build_all_slices();
  const std::vector<Vec3> points = query_points(1024);
  size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(distance_field.query(points[i]));
    i = (i + 1) & 1023;
  }
}
BENCHMARK(BM_DistanceFieldQuery);

void BM_DistanceFieldDistance(benchmark::State& state) {
  DistanceField distance_field;
  distance_field.build(wall_and_boxes(), 0, 59);
  distance_field.build_all_slices();
  const std::vector<Vec3> points = query_points(1024);
  size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(distance_field.distance(points[i]));
    i = (i + 1) & 1023;
  }
}
BENCHMARK(BM_DistanceFieldDistance);

}  // namespace
