// The 3-D occupancy map: hits become occupied, beams carve free space so
// that false returns fade, column queries for obstacle tops and seen free
// space, and forgetting far voxels.

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include <octomap/OcTree.h>

#include "ofn/mapper/occupancy_map.hpp"

namespace ofn::mapping {
namespace {

constexpr double kNaNCoordinate = std::numeric_limits<double>::quiet_NaN();

OccupancyMapConfig unit_config() {
  OccupancyMapConfig c;
  c.resolution = 1.0;
  c.max_range = 61.0;
  return c;
}

// A point (NED) at the given altitude above flat ground at 0.
Vec3 point_at_altitude(double north, double east, double altitude) {
  return Vec3(north, east, -altitude);
}

enum class Voxel { kUnknown, kFree, kOccupied };

Voxel voxel_at(const OccupancyMap& map, const Vec3& p) {
  const auto* node = map.tree().search(p.x(), p.y(), p.z());
  if (!node) return Voxel::kUnknown;
  return map.tree().isNodeOccupied(node) ? Voxel::kOccupied : Voxel::kFree;
}

// A box wall facing the sensor: front face at `north`, 1 m thick, spanning
// [east_lo, east_hi] and altitudes [0, top], on flat ground at altitude 0.
struct Wall {
  double north, east_lo, east_hi, top;
};

struct Scan {
  std::vector<Vec3> hits;
  std::vector<Vec3> free_ray_ends;
};

// A fan of beams from `sensor` (azimuth about north, elevation positive up),
// each ending on the wall face, on the ground or at max range.
Scan scan_of(const Vec3& sensor, const Wall& wall, double max_range, double elevation_lo_deg,
             double elevation_hi_deg) {
  Scan scan;
  const double sensor_alt = -sensor.z();
  for (double az = -15.0; az <= 15.0; az += 1.0) {
    for (double el = elevation_lo_deg; el <= elevation_hi_deg; el += 0.5) {
      const Vec3 dir(std::cos(deg2rad(el)) * std::cos(deg2rad(az)),
                     std::cos(deg2rad(el)) * std::sin(deg2rad(az)), -std::sin(deg2rad(el)));
      double range = max_range;
      bool hit = false;
      if (dir.x() > 0) {  // the wall's front face
        const double t = (wall.north - sensor.x()) / dir.x();
        const Vec3 p = sensor + t * dir;
        if (t < range && p.y() >= wall.east_lo && p.y() <= wall.east_hi && -p.z() >= 0 &&
            -p.z() <= wall.top) {
          range = t;
          hit = true;
        }
      }
      if (dir.z() > 0) {  // the ground
        const double t = sensor_alt / dir.z();
        if (t < range) {
          range = t;
          hit = true;
        }
      }
      // Hits sit a few centimetres inside the surface they struck.
      const Vec3 end = sensor + (hit ? range + 0.05 : range) * dir;
      (hit ? scan.hits : scan.free_ray_ends).push_back(end);
    }
  }
  return scan;
}

TEST(OccupancyMap, HitsBecomeOccupiedAndTheBeamFree) {
  OccupancyMap map(unit_config());
  const Vec3 sensor = point_at_altitude(0.5, 0.5, 10.5);
  const Vec3 hit = point_at_altitude(20.5, 0.5, 10.5);
  map.insert_scan(sensor, {hit}, {});
  EXPECT_EQ(voxel_at(map, hit), Voxel::kOccupied);
  EXPECT_EQ(voxel_at(map, point_at_altitude(10.5, 0.5, 10.5)), Voxel::kFree);
  EXPECT_EQ(voxel_at(map, point_at_altitude(21.5, 0.5, 10.5)), Voxel::kUnknown);
  EXPECT_EQ(voxel_at(map, point_at_altitude(10.5, 5.5, 10.5)), Voxel::kUnknown);
  EXPECT_GT(map.num_nodes(), 0u);
  EXPECT_GT(map.memory_bytes(), 0u);
}

TEST(OccupancyMap, FalseReturnFadesWhileARepeatedWallStays) {
  OccupancyMap map(unit_config());
  const Vec3 sensor = point_at_altitude(0.5, 0.5, 10.5);
  const Vec3 false_return = point_at_altitude(10.5, 0.5, 10.5);
  const Vec3 wall = point_at_altitude(30.5, 0.5, 10.5);
  map.insert_scan(sensor, {false_return, wall}, {});
  ASSERT_EQ(voxel_at(map, false_return), Voxel::kOccupied);
  EXPECT_GT(map.column_top(10.5, 0.5, 0.5, 1.0, 30.0), 0.0);

  // Later beams to the wall pass through the false return's voxel.
  for (int scan = 0; scan < 3; ++scan) map.insert_scan(sensor, {wall}, {});
  EXPECT_EQ(voxel_at(map, false_return), Voxel::kFree);
  EXPECT_LT(map.column_top(10.5, 0.5, 0.5, 1.0, 30.0), 0.0);
  EXPECT_EQ(voxel_at(map, wall), Voxel::kOccupied);

  // However many beams pass by, the wall hit every scan stays.
  for (int scan = 0; scan < 50; ++scan) map.insert_scan(sensor, {wall}, {});
  EXPECT_EQ(voxel_at(map, wall), Voxel::kOccupied);
}

TEST(OccupancyMap, ManyBeamsIntoOneVoxelCountOncePerScan) {
  OccupancyMap map(unit_config());
  const Vec3 sensor = point_at_altitude(0.5, 0.5, 10.5);
  const Vec3 false_return = point_at_altitude(10.5, 0.5, 10.5);
  // Forty returns in one voxel in one scan are one observation: two scans
  // of a single beam passing through must then bring it down.
  std::vector<Vec3> burst(40, false_return);
  map.insert_scan(sensor, burst, {});
  for (int scan = 0; scan < 3; ++scan)
    map.insert_scan(sensor, {}, {point_at_altitude(60.5, 0.5, 10.5)});
  EXPECT_EQ(voxel_at(map, false_return), Voxel::kFree);
}

TEST(OccupancyMap, FreeRaysCarveUpToMaxRangeOnly) {
  OccupancyMap map(unit_config());
  const Vec3 sensor = point_at_altitude(0.5, 0.5, 10.5);
  const Vec3 removed = point_at_altitude(25.5, 0.5, 10.5);
  map.insert_scan(sensor, {removed}, {});
  ASSERT_EQ(voxel_at(map, removed), Voxel::kOccupied);
  for (int scan = 0; scan < 3; ++scan)
    map.insert_scan(sensor, {}, {point_at_altitude(200.5, 0.5, 10.5)});  // beyond max range
  EXPECT_EQ(voxel_at(map, removed), Voxel::kFree);
  EXPECT_EQ(voxel_at(map, point_at_altitude(55.5, 0.5, 10.5)), Voxel::kFree);
  EXPECT_EQ(voxel_at(map, point_at_altitude(70.5, 0.5, 10.5)), Voxel::kUnknown);
}

TEST(OccupancyMap, HitsBeyondMaxRangeOnlyCarve) {
  OccupancyMap map(unit_config());
  const Vec3 sensor = point_at_altitude(0.5, 0.5, 10.5);
  map.insert_scan(sensor, {point_at_altitude(80.5, 0.5, 10.5)}, {});
  EXPECT_EQ(voxel_at(map, point_at_altitude(80.5, 0.5, 10.5)), Voxel::kUnknown);
  EXPECT_EQ(voxel_at(map, point_at_altitude(50.5, 0.5, 10.5)), Voxel::kFree);
}

TEST(OccupancyMap, IgnoresNonFiniteInput) {
  OccupancyMap map(unit_config());
  map.insert_scan(Vec3(kNaNCoordinate, 0, -10), {point_at_altitude(5.5, 0.5, 10.5)}, {});
  EXPECT_EQ(map.num_nodes(), 0u);
  map.insert_scan(point_at_altitude(0.5, 0.5, 10.5),
                  {Vec3(kNaNCoordinate, 1, 1), point_at_altitude(5.5, 0.5, 10.5)},
                  {Vec3(1, kNaNCoordinate, 1)});
  EXPECT_EQ(voxel_at(map, point_at_altitude(5.5, 0.5, 10.5)), Voxel::kOccupied);
  EXPECT_LT(map.column_top(kNaNCoordinate, 0.5, 0.5, 1.0, 30.0), 0.0);
  EXPECT_FALSE(map.column_seen_free(0.5, 0.5, 0.5, 30.0, 1.0));  // empty range
}

TEST(OccupancyMap, ColumnTopFindsASeenWallTopWithinOneVoxel) {
  OccupancyMap map(unit_config());
  const Wall wall{20.0, -5.0, 5.0, 12.0};
  const Vec3 sensor = point_at_altitude(0.0, 0.0, 20.0);
  const Scan scan = scan_of(sensor, wall, 61.0, -60.0, 10.0);
  for (int i = 0; i < 3; ++i) map.insert_scan(sensor, scan.hits, scan.free_ray_ends);

  for (double east : {-3.5, 0.5, 2.5}) {
    const double top = map.column_top(20.5, east, 0.5, 1.0, 40.0);
    EXPECT_NEAR(top, wall.top, 1.0) << "east " << east;
    EXPECT_GE(top, wall.top - 1e-9) << "the voxel top covers the wall top";
    // Beams crossed the space just over the wall: its top was seen.
    EXPECT_TRUE(map.column_seen_free(20.5, east, 0.5, top, top + 4.0)) << "east " << east;
  }
  // Cells next to the wall's voxel column do not see it, nor does the range
  // below the ground clearance pick up the ground.
  EXPECT_LT(map.column_top(19.5, 0.5, 0.5, 1.0, 40.0), 0.0);
  EXPECT_LT(map.column_top(10.5, 0.5, 0.5, 1.0, 40.0), 0.0);
  EXPECT_LT(map.column_top(20.5, 0.5, 0.5, 13.0, 40.0), 0.0);
}

TEST(OccupancyMap, TopOfATallWallSeenOnlyFromTheFaceIsNotSeenFree) {
  OccupancyMap map(unit_config());
  const Wall wall{20.0, -5.0, 5.0, 40.0};
  const Vec3 sensor = point_at_altitude(0.0, 0.0, 10.0);
  const Scan scan = scan_of(sensor, wall, 61.0, -15.0, 15.0);
  for (int i = 0; i < 3; ++i) map.insert_scan(sensor, scan.hits, scan.free_ray_ends);

  // The face is lit up to about 10 + 20 tan 15deg = 15.4 m.
  const double top = map.column_top(20.5, 0.5, 0.5, 1.0, 60.0);
  EXPECT_NEAR(top, 16.0, 1.0);
  EXPECT_FALSE(map.column_seen_free(20.5, 0.5, 0.5, top, top + 4.0));
  // The space in front of the wall was seen.
  EXPECT_TRUE(map.column_seen_free(15.5, 0.5, 0.5, 5.0, 12.0));
}

TEST(OccupancyMap, ColumnTopCanAskForMoreConfidence) {
  OccupancyMap map(unit_config());
  const Vec3 sensor = point_at_altitude(0.5, 0.5, 10.5);
  const Vec3 hit = point_at_altitude(20.5, 0.5, 10.5);
  map.insert_scan(sensor, {hit}, {});  // p = 0.7
  EXPECT_DOUBLE_EQ(map.column_top(20.5, 0.5, 0.5, 1.0, 30.0), 11.0);
  EXPECT_LT(map.column_top(20.5, 0.5, 0.5, 1.0, 30.0, 0.8), 0.0);
  map.insert_scan(sensor, {hit}, {});  // p = 0.84
  EXPECT_DOUBLE_EQ(map.column_top(20.5, 0.5, 0.5, 1.0, 30.0, 0.8), 11.0);
}

TEST(OccupancyMap, ColumnTopHonoursTheGroundAltitude) {
  OccupancyMapConfig config = unit_config();
  config.ground_altitude = 100.0;
  OccupancyMap map(config);
  map.insert_scan(Vec3(0.5, 0.5, -110.5), {Vec3(20.5, 0.5, -107.5)}, {});
  EXPECT_DOUBLE_EQ(map.column_top(20.5, 0.5, 0.5, 1.0, 30.0), 8.0);
}

TEST(OccupancyMap, ForgetFarDropsOnlyFarVoxels) {
  OccupancyMapConfig config = unit_config();
  config.forget_radius = 150.0;
  OccupancyMap map(config);
  const Vec3 near_hit = point_at_altitude(10.5, 0.5, 10.5);
  const Vec3 far_hit = point_at_altitude(220.5, 0.5, 10.5);
  map.insert_scan(point_at_altitude(0.5, 0.5, 10.5), {near_hit}, {});
  map.insert_scan(point_at_altitude(200.5, 0.5, 10.5), {far_hit}, {});
  const size_t before = map.num_nodes();
  map.forget_far(0.0, 0.0);
  EXPECT_EQ(voxel_at(map, near_hit), Voxel::kOccupied);
  EXPECT_EQ(voxel_at(map, point_at_altitude(5.5, 0.5, 10.5)), Voxel::kFree);
  EXPECT_EQ(voxel_at(map, far_hit), Voxel::kUnknown);
  EXPECT_EQ(voxel_at(map, point_at_altitude(205.5, 0.5, 10.5)), Voxel::kUnknown);
  EXPECT_LT(map.num_nodes(), before);
  for (auto it = map.tree().begin_leafs(), end = map.tree().end_leafs(); it != end; ++it)
    ASSERT_LE(std::hypot(it.getX(), it.getY()), 150.0) << "leaf left at " << it.getCoordinate();

  // The map keeps working after forgetting, also after forgetting everything.
  map.insert_scan(point_at_altitude(0.5, 0.5, 10.5), {point_at_altitude(-12.5, 0.5, 10.5)}, {});
  EXPECT_EQ(voxel_at(map, point_at_altitude(-12.5, 0.5, 10.5)), Voxel::kOccupied);
  map.forget_far(1000.0, 1000.0);
  EXPECT_EQ(map.num_nodes(), 0u);
  EXPECT_EQ(voxel_at(map, near_hit), Voxel::kUnknown);
  map.insert_scan(point_at_altitude(0.5, 0.5, 10.5), {near_hit}, {});
  EXPECT_EQ(voxel_at(map, near_hit), Voxel::kOccupied);
}

TEST(OccupancyMap, ForgetFarKeepsAWideNeighbourhoodIntact) {
  OccupancyMapConfig config = unit_config();
  config.forget_radius = 30.0;
  OccupancyMap map(config);
  // A ring of sensor positions carving a large area, then forgetting around
  // a point: everything known near it survives, everything far goes.
  for (int k = 0; k < 12; ++k) {
    const double a = 2.0 * kPi * k / 12.0;
    const Vec3 sensor = point_at_altitude(40.0 * std::cos(a), 40.0 * std::sin(a), 10.5);
    map.insert_scan(sensor, {point_at_altitude(0.5, 0.5, 10.5)},
                    {point_at_altitude(0.5, 0.5, 40.0)});
  }
  std::vector<Vec3> near_known;
  for (auto it = map.tree().begin_leafs(), end = map.tree().end_leafs(); it != end; ++it)
    if (std::hypot(it.getX() - 5.0, it.getY() + 3.0) < 29.0 && it.getSize() <= 1.0)
      near_known.push_back(Vec3(it.getX(), it.getY(), it.getZ()));
  ASSERT_GT(near_known.size(), 100u);
  map.forget_far(5.0, -3.0);
  for (const Vec3& p : near_known) ASSERT_NE(voxel_at(map, p), Voxel::kUnknown);
  for (auto it = map.tree().begin_leafs(), end = map.tree().end_leafs(); it != end; ++it)
    ASSERT_LE(std::hypot(it.getX() - 5.0, it.getY() + 3.0), 30.0);
  EXPECT_EQ(voxel_at(map, point_at_altitude(0.5, 0.5, 10.5)), Voxel::kOccupied);
}

TEST(OccupancyMap, ForgetFarKeepsEveryLeafWithinTheRadiusUnchanged) {
  OccupancyMapConfig config = unit_config();
  config.forget_radius = 23.0;
  // Centres on a node boundary, inside a node, and far from the carved area.
  for (const Vec3& centre : {Vec3(0, 0, 0), Vec3(5.3, -3.7, 0), Vec3(-31.0, 17.2, 0)}) {
    OccupancyMap map(config);
    for (int k = 0; k < 12; ++k) {
      const double a = 2.0 * kPi * k / 12.0;
      const Vec3 sensor = point_at_altitude(40.0 * std::cos(a), 40.0 * std::sin(a), 10.5);
      map.insert_scan(sensor,
                      {point_at_altitude(0.5, 0.5, 10.5), point_at_altitude(-8.5, 12.5, 3.5)},
                      {point_at_altitude(0.5, 0.5, 40.0), point_at_altitude(20.5, -30.5, 1.0)});
    }
    struct Leaf {
      Vec3 centre;
      unsigned depth;
      float log_odds;
    };
    std::vector<Leaf> kept;
    size_t far_leaves = 0;
    for (auto it = map.tree().begin_leafs(), end = map.tree().end_leafs(); it != end; ++it) {
      if (std::hypot(it.getX() - centre.x(), it.getY() - centre.y()) <= config.forget_radius)
        kept.push_back({Vec3(it.getX(), it.getY(), it.getZ()), it.getDepth(), it->getLogOdds()});
      else
        ++far_leaves;
    }
    ASSERT_GT(kept.size(), 100u);
    ASSERT_GT(far_leaves, 100u);
    map.forget_far(centre.x(), centre.y());
    size_t leaves_after = 0;
    for (auto it = map.tree().begin_leafs(), end = map.tree().end_leafs(); it != end; ++it)
      ++leaves_after;
    EXPECT_EQ(leaves_after, kept.size()) << "centre " << centre.transpose();
    for (const Leaf& leaf : kept) {
      const auto* node =
          map.tree().search(leaf.centre.x(), leaf.centre.y(), leaf.centre.z(), leaf.depth);
      ASSERT_NE(node, nullptr) << leaf.centre.transpose();
      ASSERT_EQ(node->getLogOdds(), leaf.log_odds) << leaf.centre.transpose();
    }
  }
}

TEST(OccupancyMap, RejectsBadConfigNamingTheField) {
  OccupancyMapConfig config = unit_config();
  config.prob_miss = 0.6;
  try {
    OccupancyMap map(config);
    FAIL() << "accepted prob_miss 0.6";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("prob_miss"), std::string::npos);
  }
  config = unit_config();
  config.resolution = -1.0;
  EXPECT_THROW(OccupancyMap{config}, std::invalid_argument);
}

}  // namespace
}  // namespace ofn::mapping
