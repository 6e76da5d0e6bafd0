// Blob detection on the filtered obstacle grid and the cuboids it yields for
// the global planner (paper section 3.2).

#include <gtest/gtest.h>

#include <stdexcept>
#include <vector>

#include "ofn/mapper/cuboid_extractor.hpp"

namespace ofn::mapping {
namespace {

Heightfield make_grid(int rows, int cols, double resolution = 1.0, double origin_north = 0,
                      double origin_east = 0) {
  Heightfield grid;
  grid.origin_north = origin_north;
  grid.origin_east = origin_east;
  grid.resolution = resolution;
  grid.rows = rows;
  grid.cols = cols;
  grid.top.assign(static_cast<size_t>(rows) * cols, 0.0f);
  return grid;
}

/// Fills the inclusive cell range with one top.
void fill(Heightfield& grid, int row_min, int col_min, int row_max, int col_max, float top) {
  for (int row = row_min; row <= row_max; ++row)
    for (int col = col_min; col <= col_max; ++col) grid.at(row, col) = top;
}

bool covers_cell(const Cuboid& c, const Heightfield& grid, int row, int col) {
  const double north = grid.cell_centre_north(row), east = grid.cell_centre_east(col);
  return north > c.min.x() && north < c.max.x() && east > c.min.y() && east < c.max.y();
}

double footprint_area(const Cuboid& c) {
  return (c.max.x() - c.min.x()) * (c.max.y() - c.min.y());
}

TEST(CuboidExtractor, EmptyOrFreeGridGivesNoCuboids) {
  const CuboidExtractor extractor{CuboidExtractorConfig{}};
  EXPECT_TRUE(extractor.extract(Heightfield{}).empty());
  EXPECT_TRUE(extractor.extract(make_grid(30, 30)).empty());
}

TEST(CuboidExtractor, RectangleOfCellsGivesOneCuboidWithExactCornersAndTop) {
  auto grid = make_grid(20, 20);
  fill(grid, 3, 5, 6, 10, 12.0f);
  const auto cuboids = CuboidExtractor{CuboidExtractorConfig{}}.extract(grid);
  ASSERT_EQ(cuboids.size(), 1u);
  const Cuboid& c = cuboids[0];
  EXPECT_DOUBLE_EQ(c.min.x(), 3.0);
  EXPECT_DOUBLE_EQ(c.min.y(), 5.0);
  EXPECT_DOUBLE_EQ(c.max.x(), 7.0);
  EXPECT_DOUBLE_EQ(c.max.y(), 11.0);
  EXPECT_DOUBLE_EQ(c.max.z(), 0.0);
  EXPECT_DOUBLE_EQ(c.top_altitude(), 12.0);
  EXPECT_TRUE(c.top_observed);
}

TEST(CuboidExtractor, SeparateBlobsGiveSeparateCuboidsInNorthOrder) {
  auto grid = make_grid(30, 30);
  fill(grid, 20, 2, 24, 6, 8.0f);
  fill(grid, 2, 20, 5, 25, 15.0f);
  const auto cuboids = CuboidExtractor{CuboidExtractorConfig{}}.extract(grid);
  ASSERT_EQ(cuboids.size(), 2u);
  EXPECT_DOUBLE_EQ(cuboids[0].min.x(), 2.0);
  EXPECT_DOUBLE_EQ(cuboids[0].top_altitude(), 15.0);
  EXPECT_DOUBLE_EQ(cuboids[1].min.x(), 20.0);
  EXPECT_DOUBLE_EQ(cuboids[1].top_altitude(), 8.0);
}

TEST(CuboidExtractor, SmallBlobsAndLowCellsAreIgnored) {
  CuboidExtractorConfig config;
  config.height_threshold = 1.5;
  config.min_area = 4.0;
  auto grid = make_grid(30, 30);
  fill(grid, 1, 1, 1, 3, 20.0f);     // 3 m^2: below min_area
  fill(grid, 10, 10, 15, 15, 1.0f);  // below the height threshold
  fill(grid, 20, 20, 25, 25, 1.5f);  // at the threshold is not above it
  EXPECT_TRUE(CuboidExtractor{config}.extract(grid).empty());

  fill(grid, 1, 1, 1, 4, 20.0f);  // 4 m^2: kept
  const auto cuboids = CuboidExtractor{config}.extract(grid);
  ASSERT_EQ(cuboids.size(), 1u);
  EXPECT_DOUBLE_EQ(cuboids[0].min.y(), 1.0);
  EXPECT_DOUBLE_EQ(cuboids[0].max.y(), 5.0);
}

TEST(CuboidExtractor, DiagonalNeighboursJoinOneBlob) {
  CuboidExtractorConfig config;
  config.min_area = 5.0;  // each square alone (4 m^2) would be dropped
  auto grid = make_grid(20, 20);
  fill(grid, 2, 2, 3, 3, 10.0f);
  fill(grid, 4, 4, 5, 5, 10.0f);  // touches the first square only at a corner
  const auto cuboids = CuboidExtractor{config}.extract(grid);
  ASSERT_EQ(cuboids.size(), 1u);
  EXPECT_DOUBLE_EQ(cuboids[0].min.x(), 2.0);
  EXPECT_DOUBLE_EQ(cuboids[0].max.x(), 6.0);
}

TEST(CuboidExtractor, SlantedWallBecomesStaircaseCoveringEveryCell) {
  const int n = 40;
  auto grid = make_grid(n, n + 1);
  for (int i = 0; i < n; ++i) fill(grid, i, i, i, i + 1, 25.0f);
  const auto cuboids = CuboidExtractor{CuboidExtractorConfig{}}.extract(grid);
  ASSERT_GE(cuboids.size(), 4u);

  double total_area = 0;
  for (const Cuboid& c : cuboids) {
    total_area += footprint_area(c);
    EXPECT_DOUBLE_EQ(c.top_altitude(), 25.0);
  }
  const double bounding_area = n * (n + 1.0);
  EXPECT_LT(total_area, 0.25 * bounding_area);

  for (int row = 0; row < grid.rows; ++row) {
    for (int col = 0; col < grid.cols; ++col) {
      if (grid.at(row, col) <= 0) continue;
      bool covered = false;
      for (const Cuboid& c : cuboids) covered = covered || covers_cell(c, grid, row, col);
      EXPECT_TRUE(covered) << "cell " << row << "," << col;
    }
  }
  for (size_t i = 1; i < cuboids.size(); ++i) EXPECT_LE(cuboids[i - 1].min.x(), cuboids[i].min.x());
}

TEST(CuboidExtractor, WellFilledOrSmallRectanglesAreNotSplit) {
  CuboidExtractorConfig config;
  config.min_split_size = 4.0;
  auto grid = make_grid(40, 40);
  // An L: poorly filled but no edge reaches 2 * min_split_size.
  fill(grid, 0, 0, 6, 0, 10.0f);
  fill(grid, 0, 0, 0, 6, 10.0f);
  // A solid block: large but full.
  fill(grid, 20, 20, 35, 35, 10.0f);
  EXPECT_EQ(CuboidExtractor{config}.extract(grid).size(), 2u);
}

TEST(CuboidExtractor, UnseenTopIsRaisedToCeiling) {
  CuboidExtractorConfig config;
  config.ceiling = 120.0;
  config.ground_altitude = 5.0;
  auto grid = make_grid(20, 20);
  fill(grid, 3, 5, 6, 10, 12.0f);

  std::vector<double> arguments;
  const auto unseen = [&](double min_north, double min_east, double max_north, double max_east,
                          double top_altitude) {
    arguments = {min_north, min_east, max_north, max_east, top_altitude};
    return false;
  };
  const auto cuboids = CuboidExtractor{config}.extract(grid, unseen);
  ASSERT_EQ(cuboids.size(), 1u);
  EXPECT_FALSE(cuboids[0].top_observed);
  EXPECT_DOUBLE_EQ(cuboids[0].top_altitude(), 125.0);
  EXPECT_DOUBLE_EQ(cuboids[0].max.z(), -5.0);
  EXPECT_EQ(arguments, (std::vector<double>{3.0, 5.0, 7.0, 11.0, 17.0}));

  const auto seen = [](double, double, double, double, double) { return true; };
  const auto observed = CuboidExtractor{config}.extract(grid, seen);
  ASSERT_EQ(observed.size(), 1u);
  EXPECT_TRUE(observed[0].top_observed);
  EXPECT_DOUBLE_EQ(observed[0].top_altitude(), 17.0);
}

TEST(CuboidExtractor, UnevenBlobTakesItsHighestCell) {
  auto grid = make_grid(20, 20);
  fill(grid, 4, 4, 8, 8, 6.0f);
  grid.at(6, 7) = 31.5f;
  grid.at(5, 5) = 9.0f;
  const auto cuboids = CuboidExtractor{CuboidExtractorConfig{}}.extract(grid);
  ASSERT_EQ(cuboids.size(), 1u);
  EXPECT_DOUBLE_EQ(cuboids[0].top_altitude(), 31.5);
}

TEST(CuboidExtractor, WorldCornersUseGridOriginAndResolution) {
  CuboidExtractorConfig config;
  config.ground_altitude = 10.0;
  auto grid = make_grid(20, 20, 0.5, 100.0, -50.0);
  fill(grid, 4, 2, 7, 9, 7.0f);  // 4 x 8 cells of 0.25 m^2 = 8 m^2
  const auto cuboids = CuboidExtractor{config}.extract(grid);
  ASSERT_EQ(cuboids.size(), 1u);
  const Cuboid& c = cuboids[0];
  EXPECT_DOUBLE_EQ(c.min.x(), 102.0);
  EXPECT_DOUBLE_EQ(c.max.x(), 104.0);
  EXPECT_DOUBLE_EQ(c.min.y(), -49.0);
  EXPECT_DOUBLE_EQ(c.max.y(), -45.0);
  EXPECT_DOUBLE_EQ(c.max.z(), -10.0);
  EXPECT_DOUBLE_EQ(c.min.z(), -17.0);
}

TEST(CuboidExtractor, GridFullOfObstacleIsOneBlob) {
  auto grid = make_grid(300, 300);
  fill(grid, 0, 0, 299, 299, 40.0f);
  const auto cuboids = CuboidExtractor{CuboidExtractorConfig{}}.extract(grid);
  ASSERT_EQ(cuboids.size(), 1u);
  EXPECT_DOUBLE_EQ(cuboids[0].max.x(), 300.0);
  EXPECT_DOUBLE_EQ(cuboids[0].max.y(), 300.0);
}

TEST(CuboidExtractor, InconsistentGridIsRejected) {
  auto grid = make_grid(10, 10);
  grid.top.resize(99);
  EXPECT_THROW(CuboidExtractor{CuboidExtractorConfig{}}.extract(grid), std::invalid_argument);
  grid = make_grid(10, 10, 0.0);
  EXPECT_THROW(CuboidExtractor{CuboidExtractorConfig{}}.extract(grid), std::invalid_argument);
}

}  // namespace
}  // namespace ofn::mapping
