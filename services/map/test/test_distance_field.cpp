// Distance field over the obstacle heightfield: the clearance (and its
// gradient) the receding-horizon optimiser constrains.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

#include "ofn/map/distance_field.hpp"

namespace ofn::mapping {
namespace {

constexpr double kOccupiedAbove = 0.5;

Heightfield make_grid(int rows, int cols, double resolution, double origin_north = 0,
                      double origin_east = 0) {
  Heightfield field;
  field.rows = rows;
  field.cols = cols;
  field.resolution = resolution;
  field.origin_north = origin_north;
  field.origin_east = origin_east;
  field.top.assign(static_cast<size_t>(rows) * cols, 0.0f);
  return field;
}

void add_box(Heightfield& field, int row0, int col0, int rows, int cols, float top) {
  for (int r = row0; r < row0 + rows; ++r)
    for (int c = col0; c < col0 + cols; ++c)
      if (field.inside(r, c)) field.at(r, c) = std::max(field.at(r, c), top);
}

Vec3 ned_of(double north, double east, double altitude) {
  return Vec3(north, east, -altitude);
}

// The centre-sampled signed distance by exhaustive search: outside, to the
// nearest column (horizontally to its centre, vertically to its top); inside a
// column, minus the distance to the nearest air (beside it or above a top).
double brute_force(const Heightfield& field, double north, double east, double altitude,
                   double max_distance) {
  const int row = static_cast<int>(std::floor((north - field.origin_north) / field.resolution));
  const int col = static_cast<int>(std::floor((east - field.origin_east) / field.resolution));
  const bool inside = field.inside(row, col) && field.at(row, col) > kOccupiedAbove &&
                      field.at(row, col) > altitude;
  double best = std::numeric_limits<double>::infinity();
  for (int r = 0; r < field.rows; ++r) {
    for (int c = 0; c < field.cols; ++c) {
      const double top = field.at(r, c);
      const bool occupied = top > kOccupiedAbove;
      const double dn = north - field.cell_centre_north(r);
      const double de = east - field.cell_centre_east(c);
      double vertical = 0;
      if (inside) {
        if (occupied) vertical = std::max(0.0, top - altitude);
      } else {
        if (!occupied) continue;
        vertical = std::max(0.0, altitude - top);
      }
      best = std::min(best, std::sqrt(dn * dn + de * de + vertical * vertical));
    }
  }
  best = std::min(best, max_distance);
  return inside ? -best : best;
}

Heightfield random_boxes(std::mt19937& rng, double resolution) {
  Heightfield field = make_grid(40, 40, resolution, -13.25, 7.5);
  std::uniform_int_distribution<int> position(0, 39), size(1, 10), boxes(2, 5);
  std::uniform_real_distribution<float> height(1.0f, 18.0f);
  const int count = boxes(rng);
  for (int b = 0; b < count; ++b)
    add_box(field, position(rng), position(rng), size(rng), size(rng), height(rng));
  return field;
}

TEST(DistanceField, EqualsBruteForceAtCellCentresAndSlices) {
  std::mt19937 rng(7);
  for (const double resolution : {1.0, 0.5}) {
    for (int trial = 0; trial < 4; ++trial) {
      const Heightfield field = random_boxes(rng, resolution);
      DistanceFieldConfig config;
      config.vertical_resolution = resolution == 1.0 ? 1.0 : 0.7;
      config.max_distance = 30;
      DistanceField distance_field(config);
      const double alt_lo = 0.3, alt_hi = 22;
      distance_field.build(field, alt_lo, alt_hi);
      ASSERT_FALSE(distance_field.empty());
      EXPECT_GE(alt_lo + (distance_field.slices() - 1) * config.vertical_resolution, alt_hi);
      std::uniform_int_distribution<int> cell(0, 39), slice(0, distance_field.slices() - 1);
      for (int n = 0; n < 400; ++n) {
        const int r = cell(rng), c = cell(rng), k = slice(rng);
        const double north = field.cell_centre_north(r), east = field.cell_centre_east(c);
        const double altitude = alt_lo + k * config.vertical_resolution;
        const double expected = brute_force(field, north, east, altitude, config.max_distance);
        EXPECT_NEAR(distance_field.distance(ned_of(north, east, altitude)), expected, 1e-4)
            << "resolution " << resolution << " cell " << r << "," << c << " slice " << k;
      }
    }
  }
}

TEST(DistanceField, BetweenSamplesWithinOneCellDiagonalOfBruteForce) {
  std::mt19937 rng(11);
  for (const double resolution : {1.0, 0.5}) {
    const Heightfield field = random_boxes(rng, resolution);
    DistanceFieldConfig config;
    config.vertical_resolution = resolution;
    DistanceField distance_field(config);
    distance_field.build(field, 0, 20);
    const double diagonal = std::sqrt(2 * resolution * resolution +
                                      config.vertical_resolution * config.vertical_resolution);
    const double extent = 40 * resolution;
    std::uniform_real_distribution<double> north(field.origin_north + 0.5 * resolution,
                                                 field.origin_north + extent - 0.5 * resolution);
    std::uniform_real_distribution<double> east(field.origin_east + 0.5 * resolution,
                                                field.origin_east + extent - 0.5 * resolution);
    std::uniform_real_distribution<double> altitude(0, 20);
    for (int n = 0; n < 400; ++n) {
      const Vec3 p = ned_of(north(rng), east(rng), altitude(rng));
      const double expected = brute_force(field, p.x(), p.y(), -p.z(), config.max_distance);
      EXPECT_NEAR(distance_field.distance(p), expected, diagonal) << p.transpose();
    }
  }
}

TEST(DistanceField, AboveAFlatTopGrowsOneToOneWithAltitude) {
  Heightfield field = make_grid(60, 60, 1.0);
  add_box(field, 20, 20, 20, 20, 10.0f);
  DistanceField distance_field;
  distance_field.build(field, 0, 40);
  for (double altitude = 11; altitude <= 35; altitude += 0.37) {
    const DistanceSample s = distance_field.query(ned_of(30.2, 29.7, altitude));
    EXPECT_NEAR(s.distance, altitude - 10, 1e-4) << altitude;
    EXPECT_NEAR(s.gradient.x(), 0, 1e-6);
    EXPECT_NEAR(s.gradient.y(), 0, 1e-6);
    EXPECT_NEAR(s.gradient.z(), -1, 1e-4);  // up is -z
  }
}

TEST(DistanceField, BesideATallWallGrowsOneToOneHorizontally) {
  Heightfield field = make_grid(60, 60, 0.5);
  add_box(field, 0, 10, 60, 2, 100.0f);  // east faces at 5.0 m and 6.0 m
  DistanceField distance_field;
  distance_field.build(field, 0, 20);
  const double wall_centre_east = 5.75;  // centre of the wall's eastern cells
  for (double east = 7.0; east <= 25; east += 0.5) {
    const DistanceSample s = distance_field.query(ned_of(15.0, east, 8.0));
    EXPECT_NEAR(s.distance, east - wall_centre_east, 1e-4) << east;
    EXPECT_NEAR(s.gradient.y(), 1, 1e-4) << east;
    EXPECT_NEAR(s.gradient.x(), 0, 1e-6);
    EXPECT_NEAR(s.gradient.z(), 0, 1e-6);
  }
}

TEST(DistanceField, GradientMatchesFiniteDifferences) {
  std::mt19937 rng(3);
  const Heightfield field = random_boxes(rng, 1.0);
  DistanceField distance_field;
  distance_field.build(field, 0, 20);
  std::uniform_int_distribution<int> cell(0, 38), slice(0, 19);
  std::uniform_real_distribution<double> fraction(0.1, 0.9);
  const double h = 1e-4;
  int checked = 0;
  for (int n = 0; n < 300; ++n) {
    // Away from sample planes, where the interpolant is smooth.
    const Vec3 p =
        ned_of(field.cell_centre_north(cell(rng)) + fraction(rng),
               field.cell_centre_east(cell(rng)) + fraction(rng), slice(rng) + fraction(rng));
    const DistanceSample s = distance_field.query(p);
    EXPECT_DOUBLE_EQ(s.distance, distance_field.distance(p));
    for (int axis = 0; axis < 3; ++axis) {
      Vec3 step = Vec3::Zero();
      step[axis] = h;
      const double numeric =
          (distance_field.distance(p + step) - distance_field.distance(p - step)) / (2 * h);
      EXPECT_NEAR(s.gradient[axis], numeric, 0.02 * std::abs(numeric) + 1e-3)
          << "axis " << axis << " at " << p.transpose();
    }
    ++checked;
  }
  EXPECT_EQ(checked, 300);
}

TEST(DistanceField, GradientHasUnitNormAndPointsAwayFromALoneBox) {
  Heightfield field = make_grid(80, 80, 1.0);
  add_box(field, 38, 38, 4, 4, 12.0f);  // occupies 38..42 m north and east
  DistanceField distance_field;
  distance_field.build(field, 0, 30);
  const Vec3 box_centre(40, 40, -6);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> horizontal(15, 65), altitude(0.2, 28);
  int checked = 0;
  for (int n = 0; n < 2000 && checked < 200; ++n) {
    const Vec3 p = ned_of(horizontal(rng), horizontal(rng), altitude(rng));
    const double d = distance_field.distance(p);
    if (d < 4 || d > 25) continue;  // near the box, or clamped
    const DistanceSample s = distance_field.query(p);
    EXPECT_NEAR(s.gradient.norm(), 1.0, 0.05) << p.transpose();
    const Vec3 away = p - box_centre;
    EXPECT_GT(s.gradient.dot(away), 0) << p.transpose();
    ++checked;
  }
  EXPECT_EQ(checked, 200);
}

TEST(DistanceField, InsideAColumnIsNegativeAndTheGradientPointsOut) {
  Heightfield field = make_grid(40, 40, 1.0);
  add_box(field, 10, 10, 10, 10, 15.0f);  // 10..20 m north and east, 15 m tall
  DistanceField distance_field;
  distance_field.build(field, 0, 25);

  // Near the west face (east = 10): out is -east.
  const DistanceSample west = distance_field.query(ned_of(15.3, 10.8, 6.4));
  EXPECT_LT(west.distance, 0);
  EXPECT_LT(west.gradient.y(), -0.5);
  // Near the north face (north = 20): out is +north.
  const DistanceSample north = distance_field.query(ned_of(19.6, 14.2, 3.3));
  EXPECT_LT(north.distance, 0);
  EXPECT_GT(north.gradient.x(), 0.5);
  // Just under the top: out is up (-z).
  const DistanceSample top = distance_field.query(ned_of(15.2, 14.7, 14.4));
  EXPECT_LT(top.distance, 0);
  EXPECT_LT(top.gradient.z(), -0.5);
  // Deep inside, still negative and still pointing somewhere out.
  const DistanceSample deep = distance_field.query(ned_of(13.4, 15.1, 5.0));
  EXPECT_LT(deep.distance, -2.0);
  EXPECT_GT(deep.gradient.norm(), 0.5);

  // The sign changes at the face, half-way between the centres either side.
  EXPECT_NEAR(distance_field.distance(ned_of(15.5, 10.0, 6.0)), 0.0, 1e-4);
  EXPECT_NEAR(distance_field.distance(ned_of(15.5, 14.5, 15.0)), 0.0, 1e-4);
}

TEST(DistanceField, EmptyHeightfieldIsMaxDistanceEverywhere) {
  DistanceFieldConfig config;
  config.max_distance = 12;
  DistanceField distance_field(config);
  EXPECT_TRUE(distance_field.empty());
  EXPECT_EQ(distance_field.distance(Vec3(1, 2, -3)), 12);

  distance_field.build(make_grid(30, 30, 1.0), 0, 10);
  EXPECT_FALSE(distance_field.empty());
  for (const Vec3& p : {Vec3(0, 0, 0), Vec3(15.5, 3.2, -7.7), Vec3(-100, 50, 20)}) {
    const DistanceSample s = distance_field.query(p);
    EXPECT_EQ(s.distance, 12);
    EXPECT_EQ(s.gradient, Vec3::Zero());
  }

  distance_field.build(make_grid(0, 0, 1.0), 0, 10);
  EXPECT_TRUE(distance_field.empty());
  EXPECT_EQ(distance_field.query(Vec3(1, 2, -3)).distance, 12);
}

TEST(DistanceField, ClampsAtMaxDistance) {
  Heightfield field = make_grid(40, 40, 1.0);
  add_box(field, 0, 0, 2, 2, 5.0f);
  DistanceFieldConfig config;
  config.max_distance = 8;
  DistanceField distance_field(config);
  distance_field.build(field, 0, 20);
  double largest = 0;
  for (double north = 0.5; north < 40; north += 1.3)
    for (double east = 0.5; east < 40; east += 1.7)
      for (double altitude = 0; altitude <= 20; altitude += 2.3)
        largest = std::max(largest, distance_field.distance(ned_of(north, east, altitude)));
  EXPECT_EQ(largest, 8);
  const DistanceSample far = distance_field.query(ned_of(30.3, 30.6, 10.2));
  EXPECT_EQ(far.distance, 8);
  EXPECT_EQ(far.gradient, Vec3::Zero());
  // Still exact inside the clamp radius.
  EXPECT_NEAR(distance_field.distance(ned_of(1.5, 6.5, 3.0)), 5.0, 1e-4);
}

TEST(DistanceField, OutsideTheVolumeUsesTheBoundaryWithZeroGradientAcross) {
  Heightfield field = make_grid(20, 20, 1.0, 100, 200);
  add_box(field, 5, 5, 3, 3, 6.0f);
  DistanceField distance_field;
  distance_field.build(field, 2, 12);
  // West of the grid (east below the first centre at 200.5).
  const Vec3 beyond = ned_of(103.2, 190, 8.6);
  const Vec3 edge = ned_of(103.2, 200.5, 8.6);
  const DistanceSample s = distance_field.query(beyond);
  EXPECT_DOUBLE_EQ(s.distance, distance_field.distance(edge));
  EXPECT_EQ(s.gradient.y(), 0);
  EXPECT_NE(s.gradient.x(), 0);
  EXPECT_NE(s.gradient.z(), 0);
  // Below the lowest slice and above the highest.
  EXPECT_DOUBLE_EQ(distance_field.distance(ned_of(103.2, 209.1, -5)),
                   distance_field.distance(ned_of(103.2, 209.1, 2)));
  const DistanceSample high = distance_field.query(ned_of(103.2, 209.1, 50));
  EXPECT_DOUBLE_EQ(high.distance, distance_field.distance(ned_of(103.2, 209.1, 12)));
  EXPECT_EQ(high.gradient.z(), 0);
}

TEST(DistanceField, RebuildingReplacesTheWholeField) {
  std::mt19937 rng(19);
  const Heightfield first = random_boxes(rng, 1.0);  // every top at or above 1 m
  Heightfield second = make_grid(25, 31, 0.5, 3, -4);
  add_box(second, 4, 6, 5, 9, 3.0f);
  add_box(second, 15, 2, 3, 20, 7.5f);
  // Bands wholly below every top as well as bands above some of them.
  for (const double first_hi : {0.8, 30.0}) {
    for (const double second_hi : {2.5, 9.0}) {
      DistanceField reused;
      reused.build(first, 0, first_hi);
      reused.build_all_slices();
      reused.build(second, 1, second_hi);
      DistanceField fresh;
      fresh.build(second, 1, second_hi);
      ASSERT_EQ(reused.slices(), fresh.slices());
      std::uniform_real_distribution<double> north(0, 20), east(-6, 14), altitude(0, 10);
      for (int n = 0; n < 300; ++n) {
        const Vec3 p = ned_of(north(rng), east(rng), altitude(rng));
        EXPECT_EQ(reused.distance(p), fresh.distance(p))
            << p.transpose() << " bands " << first_hi << ", " << second_hi;
      }
    }
  }
}

TEST(DistanceField, BuildsASliceOnlyWhenAQueryNeedsIt) {
  Heightfield field = make_grid(30, 30, 1.0);
  add_box(field, 10, 10, 4, 4, 12.0f);
  DistanceField distance_field;
  distance_field.build(field, 0, 40);
  ASSERT_EQ(distance_field.slices(), 41);
  EXPECT_EQ(distance_field.slices_built(), 0);
  distance_field.query(ned_of(5, 5, 20.5));  // between slices 20 and 21
  EXPECT_EQ(distance_field.slices_built(), 2);
  distance_field.distance(ned_of(25, 2, 21.0));  // on slice 21, interpolating towards 22
  EXPECT_EQ(distance_field.slices_built(), 3);
  distance_field.distance(ned_of(25, 2, 20.2));  // both built already
  EXPECT_EQ(distance_field.slices_built(), 3);
  Heightfield taller = field;
  add_box(taller, 10, 10, 1, 1, 13.0f);
  distance_field.build(taller, 0, 40);
  EXPECT_EQ(distance_field.slices_built(), 0);
  distance_field.build_all_slices();
  EXPECT_EQ(distance_field.slices_built(), 41);
}

TEST(DistanceField, ABuildOnTheSameInputKeepsItsSlices) {
  Heightfield field = make_grid(30, 30, 1.0);
  add_box(field, 10, 10, 4, 4, 12.0f);
  field.top[0] = 0.25f;  // below occupied_above: free, as 0 is
  DistanceField distance_field;
  distance_field.build(field, 0, 40);
  const Vec3 probe = ned_of(5, 5, 20.5);
  const DistanceSample before = distance_field.query(probe);
  ASSERT_EQ(distance_field.slices_built(), 2);

  Heightfield same = field;
  same.top[0] = 0.0f;  // another free value: the same field
  distance_field.build(same, 0, 40);
  EXPECT_EQ(distance_field.slices_built(), 2);
  const DistanceSample after = distance_field.query(probe);
  EXPECT_EQ(after.distance, before.distance);
  EXPECT_EQ(after.gradient, before.gradient);
  EXPECT_EQ(distance_field.slices_built(), 2);

  // Any difference a transform would see starts afresh: a band, a
  // threshold, the origin or one top.
  const auto rebuilt = [&](const Heightfield& input, double alt_lo, double alt_hi,
                           double occupied_above) {
    distance_field.build(field, 0, 40);
    distance_field.query(probe);
    distance_field.build(input, alt_lo, alt_hi, occupied_above);
    return distance_field.slices_built() == 0;
  };
  EXPECT_TRUE(rebuilt(field, 1, 40, 0.5));
  EXPECT_TRUE(rebuilt(field, 0, 41, 0.5));
  EXPECT_TRUE(rebuilt(field, 0, 40, 0.2));
  Heightfield moved = field;
  moved.origin_north += 0.5;
  EXPECT_TRUE(rebuilt(moved, 0, 40, 0.5));
  Heightfield raised = field;
  raised.top[static_cast<size_t>(12 * 30 + 12)] = 12.5f;
  EXPECT_TRUE(rebuilt(raised, 0, 40, 0.5));

  // A rebuilt field answers as a fresh one does.
  DistanceField fresh;
  fresh.build(raised, 0, 40);
  EXPECT_EQ(distance_field.query(probe).distance, fresh.query(probe).distance);
}

TEST(DistanceField, SlicesBuiltInAnyOrderEqualAnEagerBuild) {
  std::mt19937 rng(23);
  for (int trial = 0; trial < 4; ++trial) {
    const Heightfield field = random_boxes(rng, trial % 2 ? 0.5 : 1.0);
    DistanceField eager;
    eager.build(field, 0.5, 25);
    eager.build_all_slices();
    DistanceField lazy;
    lazy.build(field, 0.5, 25);
    // From the top down, so the slices every column reaches (which share one
    // transform) come after the others.
    std::uniform_real_distribution<double> north(-14, 8), east(6, 28);
    for (double altitude = 26; altitude > -1; altitude -= 0.37) {
      for (int n = 0; n < 20; ++n) {
        const Vec3 p = ned_of(north(rng), east(rng), altitude);
        const DistanceSample a = lazy.query(p), b = eager.query(p);
        ASSERT_EQ(a.distance, b.distance) << p.transpose();
        ASSERT_EQ(a.gradient, b.gradient) << p.transpose();
      }
    }
    EXPECT_EQ(lazy.slices_built(), lazy.slices());
  }
}

TEST(DistanceField, RejectsBadArguments) {
  const Heightfield field = make_grid(10, 10, 1.0);
  DistanceField distance_field;
  EXPECT_THROW(distance_field.build(field, 10, 5), std::invalid_argument);
  Heightfield short_tops = field;
  short_tops.top.pop_back();
  EXPECT_THROW(distance_field.build(short_tops, 0, 5), std::invalid_argument);
  DistanceFieldConfig config;
  config.vertical_resolution = 0;
  EXPECT_THROW(DistanceField(config).build(field, 0, 5), std::invalid_argument);
  config = DistanceFieldConfig{};
  config.max_distance = -1;
  EXPECT_THROW(DistanceField(config).build(field, 0, 5), std::invalid_argument);
}

}  // namespace
}  // namespace ofn::mapping
