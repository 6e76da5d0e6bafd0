// The vehicle-attached obstacle grid: highest hit per cell, ground and
// ceiling handling, safety-margin inflation, conservative smoothing, and
// moving with the vehicle.

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <set>
#include <stdexcept>
#include <utility>
#include <vector>

#include "ofn/mapper/obstacle_grid.hpp"

namespace ofn::mapping {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// 20 x 20 cells of 1 m around the origin, no margin and no smoothing unless a
// test asks for them.
ObstacleGridConfig small_config() {
  ObstacleGridConfig c;
  c.resolution = 1.0;
  c.half_extent = 10.0;
  c.safety_margin = 0.0;
  c.smoothing_radius = 0;
  c.ground_altitude = 0.0;
  c.ground_clearance = 1.0;
  c.ceiling = 50.0;
  return c;
}

// A world point (NED) at the given altitude above flat ground at 0.
Vec3 at_altitude(double north, double east, double altitude) {
  return Vec3(north, east, -altitude);
}

float raw_top_at(const ObstacleGrid& grid, double north, double east) {
  const Heightfield& raw = grid.raw();
  const int row = raw.row_of(north), col = raw.col_of(east);
  return raw.inside(row, col) ? raw.at(row, col) : -1.0f;
}

std::set<std::pair<int, int>> nonzero_cells(const Heightfield& h) {
  std::set<std::pair<int, int>> cells;
  for (int r = 0; r < h.rows; ++r)
    for (int c = 0; c < h.cols; ++c)
      if (h.at(r, c) > 0.0f) cells.insert({r, c});
  return cells;
}

TEST(Heightfield, CellIndexFloorsTowardsNegativeInfinity) {
  Heightfield h;
  h.origin_north = -10.0;
  h.origin_east = 5.0;
  h.resolution = 2.0;
  EXPECT_EQ(h.row_of(-10.0), 0);
  EXPECT_EQ(h.row_of(-8.01), 0);
  EXPECT_EQ(h.row_of(-8.0), 1);
  EXPECT_EQ(h.row_of(-10.5), -1);
  EXPECT_EQ(h.col_of(4.9), -1);
  EXPECT_EQ(h.col_of(9.5), 2);
  EXPECT_LT(h.row_of(kNaN), 0);
  EXPECT_GT(h.col_of(1e300), 1000000);
}

TEST(ObstacleGrid, IsSquareAndCentredOnTheStart) {
  ObstacleGridConfig config = small_config();
  config.half_extent = 70.0;
  ObstacleGrid grid(config);
  EXPECT_EQ(grid.raw().rows, 140);
  EXPECT_EQ(grid.raw().cols, 140);
  EXPECT_DOUBLE_EQ(grid.raw().origin_north, -70.0);
  EXPECT_DOUBLE_EQ(grid.raw().origin_east, -70.0);

  config.half_extent = 10.2;  // rounded up to whole cells
  ObstacleGrid rounded(config);
  EXPECT_EQ(rounded.raw().rows, 21);
  EXPECT_DOUBLE_EQ(rounded.raw().origin_north + 0.5 * rounded.raw().rows, 0.0);
}

TEST(ObstacleGrid, KeepsTheHighestHitPerCell) {
  ObstacleGrid grid(small_config());
  const std::vector<Vec3> hits = {at_altitude(2.5, 3.5, 5.0), at_altitude(2.2, 3.9, 12.0),
                                  at_altitude(2.7, 3.1, 8.0), at_altitude(-4.5, 1.5, 3.0)};
  EXPECT_EQ(grid.insert_hits(hits), 4);
  EXPECT_FLOAT_EQ(raw_top_at(grid, 2.5, 3.5), 12.0f);
  EXPECT_FLOAT_EQ(raw_top_at(grid, -4.5, 1.5), 3.0f);
  EXPECT_EQ(nonzero_cells(grid.raw()).size(), 2u);

  // A lower hit later does not lower the cell.
  grid.insert_hits({at_altitude(2.5, 3.5, 2.0)});
  EXPECT_FLOAT_EQ(raw_top_at(grid, 2.5, 3.5), 12.0f);
}

TEST(ObstacleGrid, IgnoresGroundHitsAndClampsAtTheCeiling) {
  ObstacleGridConfig config = small_config();
  config.ground_altitude = 10.0;  // ground at 10 m altitude (z = -10)
  ObstacleGrid grid(config);
  const std::vector<Vec3> hits = {Vec3(1.5, 1.5, -10.0), Vec3(1.5, 1.5, -10.9),
                                  Vec3(2.5, 2.5, -13.0), Vec3(3.5, 3.5, -200.0)};
  EXPECT_EQ(grid.insert_hits(hits), 2);
  EXPECT_FLOAT_EQ(raw_top_at(grid, 1.5, 1.5), 0.0f);
  EXPECT_FLOAT_EQ(raw_top_at(grid, 2.5, 2.5), 3.0f);
  EXPECT_FLOAT_EQ(raw_top_at(grid, 3.5, 3.5), 50.0f);
}

TEST(ObstacleGrid, IgnoresPointsOffTheGridAndNonFinitePoints) {
  ObstacleGrid grid(small_config());
  const std::vector<Vec3> hits = {at_altitude(10.5, 0.5, 5.0), at_altitude(0.5, -10.5, 5.0),
                                  Vec3(kNaN, 0.5, -5.0), Vec3(0.5, 0.5, kNaN),
                                  at_altitude(9.5, -10.0, 5.0)};
  EXPECT_EQ(grid.insert_hits(hits), 1);
  EXPECT_EQ(nonzero_cells(grid.raw()).size(), 1u);
  EXPECT_FLOAT_EQ(raw_top_at(grid, 9.5, -9.5), 5.0f);
}

TEST(ObstacleGrid, MarginInflatesExactlyOverTheDisc) {
  ObstacleGridConfig config = small_config();
  config.safety_margin = 1.5;
  ObstacleGrid grid(config);
  grid.insert_hits({at_altitude(2.5, 3.5, 7.0)});
  const int row = grid.raw().row_of(2.5), col = grid.raw().col_of(3.5);

  // Cell centres within 1.5 m: the 3 x 3 block (diagonal 1.41 m); the next
  // ring (2 m and beyond) stays free.
  std::set<std::pair<int, int>> expected;
  for (int dr = -1; dr <= 1; ++dr)
    for (int dc = -1; dc <= 1; ++dc) expected.insert({row + dr, col + dc});
  const Heightfield& filtered = grid.filtered();
  EXPECT_EQ(nonzero_cells(filtered), expected);
  for (const auto& [r, c] : expected) EXPECT_FLOAT_EQ(filtered.at(r, c), 7.0f);

  // 2 m reaches the straight neighbours two cells away but not (2, 1) at 2.24 m.
  config.safety_margin = 2.0;
  ObstacleGrid wider(config);
  wider.insert_hits({at_altitude(2.5, 3.5, 7.0)});
  const auto cells = nonzero_cells(wider.filtered());
  EXPECT_EQ(cells.size(), 13u);
  EXPECT_TRUE(cells.count({row + 2, col}));
  EXPECT_TRUE(cells.count({row, col - 2}));
  EXPECT_FALSE(cells.count({row + 2, col + 1}));
}

TEST(ObstacleGrid, MarginTakesTheHighestNeighbour) {
  ObstacleGridConfig config = small_config();
  config.safety_margin = 1.0;
  ObstacleGrid grid(config);
  grid.insert_hits({at_altitude(0.5, 0.5, 4.0), at_altitude(0.5, 2.5, 9.0)});
  const Heightfield& filtered = grid.filtered();
  EXPECT_FLOAT_EQ(filtered.at(filtered.row_of(0.5), filtered.col_of(1.5)), 9.0f);
  EXPECT_FLOAT_EQ(filtered.at(filtered.row_of(0.5), filtered.col_of(0.5)), 4.0f);
}

TEST(ObstacleGrid, SmoothingNeverLowersAndRampsOutward) {
  ObstacleGridConfig sharp_config = small_config();
  sharp_config.safety_margin = 1.0;
  ObstacleGridConfig smooth_config = sharp_config;
  smooth_config.smoothing_radius = 1;
  ObstacleGrid sharp(sharp_config), smooth(smooth_config);
  // A wall along east at north 0.5, 10 m tall, plus a lone 6 m post.
  std::vector<Vec3> hits;
  for (double east = -5.5; east <= 5.5; east += 1.0) hits.push_back(at_altitude(0.5, east, 10.0));
  hits.push_back(at_altitude(-6.5, -6.5, 6.0));
  sharp.insert_hits(hits);
  smooth.insert_hits(hits);
  const Heightfield& inflated = sharp.filtered();
  const Heightfield& filtered = smooth.filtered();

  for (int r = 0; r < filtered.rows; ++r)
    for (int c = 0; c < filtered.cols; ++c) {
      ASSERT_GE(filtered.at(r, c), inflated.at(r, c)) << r << "," << c;
      ASSERT_GE(filtered.at(r, c), smooth.raw().at(r, c)) << r << "," << c;
    }

  // North of the wall: margin cell at full height, then a ramp, then free.
  const double east = 0.5;
  const float margin_cell = filtered.at(filtered.row_of(1.5), filtered.col_of(east));
  const float ramp_cell = filtered.at(filtered.row_of(2.5), filtered.col_of(east));
  const float beyond = filtered.at(filtered.row_of(3.5), filtered.col_of(east));
  EXPECT_FLOAT_EQ(margin_cell, 10.0f);
  EXPECT_GT(ramp_cell, 0.0f);
  EXPECT_LT(ramp_cell, margin_cell);
  EXPECT_FLOAT_EQ(ramp_cell, 10.0f / 3.0f);  // one of three window rows holds the wall margin
  EXPECT_FLOAT_EQ(beyond, 0.0f);
  EXPECT_FLOAT_EQ(inflated.at(inflated.row_of(2.5), inflated.col_of(east)), 0.0f);
}

TEST(ObstacleGrid, FilteredFollowsLaterChanges) {
  ObstacleGrid grid(small_config());
  EXPECT_TRUE(nonzero_cells(grid.filtered()).empty());
  grid.insert_hits({at_altitude(0.5, 0.5, 4.0)});
  EXPECT_EQ(nonzero_cells(grid.filtered()).size(), 1u);
  grid.insert_hits({at_altitude(-0.5, 0.5, 4.0)});
  EXPECT_EQ(nonzero_cells(grid.filtered()).size(), 2u);
}

TEST(ObstacleGrid, RecentreKeepsHitsAtTheirWorldPosition) {
  ObstacleGrid grid(small_config());
  const Vec3 hit = at_altitude(3.5, -2.5, 7.0);
  grid.insert_hits({hit});
  const std::vector<std::pair<double, double>> path = {{4.2, 0.0},   {4.2, 5.7},  {-3.1, 5.7},
                                                       {-3.1, -6.4}, {6.8, -6.4}, {0.3, 0.2}};
  for (const auto& [north, east] : path) {
    grid.recentre(north, east);
    const Heightfield& raw = grid.raw();
    EXPECT_LE(std::abs(raw.origin_north + 0.5 * raw.rows - north), 0.5 + 1e-9);
    EXPECT_LE(std::abs(raw.origin_east + 0.5 * raw.cols - east), 0.5 + 1e-9);
    // The origin stays on the starting lattice of whole cells.
    EXPECT_DOUBLE_EQ(raw.origin_north, std::round(raw.origin_north));
    EXPECT_FLOAT_EQ(raw_top_at(grid, 3.5, -2.5), 7.0f) << "vehicle at " << north << "," << east;
    EXPECT_EQ(nonzero_cells(raw).size(), 1u);
    EXPECT_EQ(nonzero_cells(grid.filtered()).size(), 1u);
  }
}

TEST(ObstacleGrid, RecentreDropsCellsThatLeaveAndClearsEnteringOnes) {
  ObstacleGrid grid(small_config());
  grid.insert_hits({at_altitude(-8.5, 0.5, 7.0), at_altitude(8.5, 0.5, 5.0)});
  grid.recentre(6.0, 0.0);  // the south hit leaves the grid, the north one stays
  EXPECT_FLOAT_EQ(raw_top_at(grid, 8.5, 0.5), 5.0f);
  EXPECT_FLOAT_EQ(raw_top_at(grid, -8.5, 0.5), -1.0f);
  grid.recentre(0.0, 0.0);  // back: the south cell re-enters empty
  EXPECT_FLOAT_EQ(raw_top_at(grid, -8.5, 0.5), 0.0f);
  EXPECT_FLOAT_EQ(raw_top_at(grid, 8.5, 0.5), 5.0f);
  EXPECT_EQ(nonzero_cells(grid.raw()).size(), 1u);

  grid.recentre(500.0, -300.0);  // a jump beyond the grid clears it
  EXPECT_TRUE(nonzero_cells(grid.raw()).empty());
  EXPECT_TRUE(nonzero_cells(grid.filtered()).empty());
}

TEST(ObstacleGrid, RecentreWaitsForAWholeCell) {
  ObstacleGrid grid(small_config());
  grid.recentre(0.9, -0.9);
  EXPECT_DOUBLE_EQ(grid.raw().origin_north, -10.0);
  EXPECT_DOUBLE_EQ(grid.raw().origin_east, -10.0);
  grid.recentre(1.0, -1.6);
  EXPECT_DOUBLE_EQ(grid.raw().origin_north, -9.0);
  EXPECT_DOUBLE_EQ(grid.raw().origin_east, -12.0);
  grid.recentre(kNaN, 0.0);
  EXPECT_DOUBLE_EQ(grid.raw().origin_north, -9.0);
}

TEST(ObstacleGrid, LowerCellLowersOrClearsButNeverRaises) {
  ObstacleGridConfig config = small_config();
  config.safety_margin = 1.0;
  ObstacleGrid grid(config);
  grid.insert_hits({at_altitude(0.5, 0.5, 9.0)});
  const int row = grid.raw().row_of(0.5), col = grid.raw().col_of(0.5);
  EXPECT_FLOAT_EQ(grid.filtered().at(row + 1, col), 9.0f);

  grid.lower_cell(row, col, 12.0f);
  EXPECT_FLOAT_EQ(grid.raw().at(row, col), 9.0f);
  grid.lower_cell(row, col, 4.0f);
  EXPECT_FLOAT_EQ(grid.raw().at(row, col), 4.0f);
  EXPECT_FLOAT_EQ(grid.filtered().at(row + 1, col), 4.0f);
  grid.lower_cell(row, col, 0.0f);
  EXPECT_TRUE(nonzero_cells(grid.filtered()).empty());
  grid.lower_cell(-1, 500, 0.0f);  // off the grid: no effect, no crash
}

TEST(ObstacleGrid, RejectsBadConfigNamingTheField) {
  ObstacleGridConfig config = small_config();
  config.resolution = 0.0;
  try {
    ObstacleGrid grid(config);
    FAIL() << "accepted resolution 0";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("resolution"), std::string::npos);
  }
  config = small_config();
  config.smoothing_radius = -1;
  EXPECT_THROW(ObstacleGrid{config}, std::invalid_argument);
  config = small_config();
  config.safety_margin = kNaN;
  EXPECT_THROW(ObstacleGrid{config}, std::invalid_argument);
}

}  // namespace
}  // namespace ofn::mapping
