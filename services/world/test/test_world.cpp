// World geometry: exact ray casts and distances for boxes, cylinders, trees
// and the ground, the seeded tree canopy, and the pop-up schedule.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <random>
#include <vector>

#include "ofn/world/world.hpp"

namespace ofn::world {
namespace {

ObstacleSpec box(int id, double north, double east, double length, double width, double height,
                 double yaw_deg = 0) {
  ObstacleSpec s;
  s.kind = ObstacleSpec::Kind::kBox;
  s.id = id;
  s.north = north;
  s.east = east;
  s.length = length;
  s.width = width;
  s.height = height;
  s.yaw = deg2rad(yaw_deg);
  return s;
}

ObstacleSpec cylinder(int id, double north, double east, double diameter, double height) {
  ObstacleSpec s = box(id, north, east, diameter, diameter, height);
  s.kind = ObstacleSpec::Kind::kCylinder;
  return s;
}

ObstacleSpec tree(int id, double north, double east, double length, double width, double height,
                  int seed) {
  ObstacleSpec s = box(id, north, east, length, width, height);
  s.kind = ObstacleSpec::Kind::kTree;
  s.seed = seed;
  return s;
}

Vec3 unit(double x, double y, double z) {
  return Vec3(x, y, z).normalized();
}

/// First t where the ray comes within `tolerance` of the obstacle, by sphere
/// tracing with distance(): an independent check of ray_cast.
std::optional<double> march(const Obstacle& o, const Vec3& origin, const Vec3& dir,
                            double max_range, double tolerance = 1e-4) {
  double t = 0;
  while (t <= max_range) {
    const double d = o.distance(origin + t * dir);
    if (d <= tolerance) return t;
    t += std::max(d, tolerance);
  }
  return std::nullopt;
}

/// Nearest of a dense set of surface samples: an independent check of distance().
double brute_force_distance(const std::vector<Vec3>& surface, const Vec3& p) {
  double best = std::numeric_limits<double>::infinity();
  for (const Vec3& s : surface) best = std::min(best, (s - p).norm());
  return best;
}

std::vector<Vec3> box_surface(const ObstacleSpec& s, double ground_z, double step) {
  std::vector<Vec3> out;
  const double c = std::cos(s.yaw), sn = std::sin(s.yaw);
  const Vec3 half(0.5 * s.length, 0.5 * s.width, 0.5 * s.height);
  const Vec3 centre(s.north, s.east, ground_z - 0.5 * s.height);
  auto add = [&](const Vec3& local) {
    out.push_back(centre +
                  Vec3(c * local.x() - sn * local.y(), sn * local.x() + c * local.y(), local.z()));
  };
  for (int axis = 0; axis < 3; ++axis) {
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    const int nu = static_cast<int>(std::ceil(2 * half[u] / step));
    const int nv = static_cast<int>(std::ceil(2 * half[v] / step));
    for (int side : {-1, 1})
      for (int i = 0; i <= nu; ++i)
        for (int j = 0; j <= nv; ++j) {
          Vec3 local;
          local[axis] = side * half[axis];
          local[u] = -half[u] + 2 * half[u] * i / nu;
          local[v] = -half[v] + 2 * half[v] * j / nv;
          add(local);
        }
  }
  return out;
}

std::vector<Vec3> cylinder_surface(double north, double east, double radius, double z_top,
                                   double z_bottom, double step) {
  std::vector<Vec3> out;
  const int around = static_cast<int>(std::ceil(2 * kPi * radius / step));
  const int up = static_cast<int>(std::ceil((z_bottom - z_top) / step));
  const int rings = static_cast<int>(std::ceil(radius / step));
  for (int i = 0; i < around; ++i) {
    const double a = 2 * kPi * i / around;
    for (int j = 0; j <= up; ++j)
      out.emplace_back(north + radius * std::cos(a), east + radius * std::sin(a),
                       z_top + (z_bottom - z_top) * j / up);
    for (int k = 0; k <= rings; ++k)
      for (double z : {z_top, z_bottom})
        out.emplace_back(north + radius * k / rings * std::cos(a),
                         east + radius * k / rings * std::sin(a), z);
  }
  return out;
}

std::vector<Vec3> sphere_surface(const Vec3& centre, double radius, int count) {
  std::vector<Vec3> out;
  const double golden = kPi * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < count; ++i) {
    const double z = 1.0 - 2.0 * (i + 0.5) / count;
    const double r = std::sqrt(1.0 - z * z);
    out.push_back(centre + radius * Vec3(r * std::cos(golden * i), r * std::sin(golden * i), z));
  }
  return out;
}

/// Random points around an obstacle's bounds, outside it.
std::vector<Vec3> points_around(const Obstacle& o, int count, unsigned seed) {
  std::mt19937 rng(seed);
  const Vec3 margin = Vec3::Constant(3.0);
  const Vec3 lo = o.bounds_min() - margin, hi = o.bounds_max() + margin;
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Vec3> out;
  while (static_cast<int>(out.size()) < count) {
    const Vec3 p(lo.x() + u(rng) * (hi.x() - lo.x()), lo.y() + u(rng) * (hi.y() - lo.y()),
                 lo.z() + u(rng) * (hi.z() - lo.z()));
    if (!o.contains(p)) out.push_back(p);
  }
  return out;
}

/// Rays from random points around the obstacle aimed near its centre: the
/// ray cast agrees with sphere tracing on distance().
void expect_ray_cast_agrees_with_distance(const Obstacle& o, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> jitter(-2.0, 2.0);
  const Vec3 centre = 0.5 * (o.bounds_min() + o.bounds_max());
  int hits = 0, misses = 0;
  for (const Vec3& origin : points_around(o, 200, seed)) {
    const Vec3 aim = centre + Vec3(jitter(rng), jitter(rng), jitter(rng));
    const Vec3 dir = (aim - origin).normalized();
    const auto cast = o.ray_cast(origin, dir, 100.0);
    const auto marched = march(o, origin, dir, 100.0);
    ASSERT_EQ(cast.has_value(), marched.has_value())
        << "origin " << origin.transpose() << " dir " << dir.transpose();
    if (cast) {
      EXPECT_NEAR(*cast, *marched, 5e-3);
      EXPECT_NEAR(o.distance(origin + *cast * dir), 0.0, 1e-9);
      ++hits;
    } else {
      ++misses;
    }
  }
  EXPECT_GT(hits, 20);
  EXPECT_GT(misses, 0);
}

TEST(WorldBox, AxisAlignedRaysHitTheFacesAtTheAnalyticRange) {
  // 4 m along north, 2 m along east, 5 m tall, centred 10 m north.
  const Obstacle o(box(1, 10, 0, 4, 2, 5));
  EXPECT_NEAR(*o.ray_cast(Vec3(0, 0, -2), unit(1, 0, 0), 100), 8.0, 1e-12);
  EXPECT_NEAR(*o.ray_cast(Vec3(20, 0, -2), unit(-1, 0, 0), 100), 8.0, 1e-12);
  EXPECT_NEAR(*o.ray_cast(Vec3(10, -10, -2), unit(0, 1, 0), 100), 9.0, 1e-12);
  EXPECT_NEAR(*o.ray_cast(Vec3(10, 0, -20), unit(0, 0, 1), 100), 15.0, 1e-12);
  // Slanted down onto the front face: x reaches 8 after 8 / cos(20 deg).
  const Vec3 slant = unit(std::cos(deg2rad(20)), 0, std::sin(deg2rad(20)));
  EXPECT_NEAR(*o.ray_cast(Vec3(0, 0, -4), slant, 100), 8.0 / std::cos(deg2rad(20)), 1e-9);
  // Over the top and beside it.
  EXPECT_FALSE(o.ray_cast(Vec3(0, 0, -5.5), unit(1, 0, 0), 100));
  EXPECT_FALSE(o.ray_cast(Vec3(0, 1.001, -2), unit(1, 0, 0), 100));
  EXPECT_FALSE(o.ray_cast(Vec3(0, 0, -2), unit(-1, 0, 0), 100));
  // Beyond max_range.
  EXPECT_FALSE(o.ray_cast(Vec3(0, 0, -2), unit(1, 0, 0), 7.9));
}

TEST(WorldBox, GrazingRaysTouchTheEdgeAndJustOutsideMiss) {
  const Obstacle o(box(1, 10, 0, 4, 2, 5));
  EXPECT_NEAR(*o.ray_cast(Vec3(0, 0.999999, -2), unit(1, 0, 0), 100), 8.0, 1e-9);
  EXPECT_FALSE(o.ray_cast(Vec3(0, 1.000001, -2), unit(1, 0, 0), 100));
  EXPECT_NEAR(*o.ray_cast(Vec3(0, 0, -4.999999), unit(1, 0, 0), 100), 8.0, 1e-9);
  EXPECT_FALSE(o.ray_cast(Vec3(0, 0, -5.000001), unit(1, 0, 0), 100));
}

TEST(WorldBox, YawedBoxIsHitAlongItsOwnAxes) {
  // 4 m along its x, 2 m along its y, yawed 45 deg from north towards east.
  const Obstacle o(box(1, 5, 5, 4, 2, 5, 45));
  const Vec3 centre(5, 5, -2);
  const Vec3 box_x = unit(1, 1, 0), box_y = unit(-1, 1, 0);
  EXPECT_NEAR(*o.ray_cast(centre - 10 * box_x, box_x, 100), 8.0, 1e-9);
  EXPECT_NEAR(*o.ray_cast(centre + 10 * box_x, -box_x, 100), 8.0, 1e-9);
  EXPECT_NEAR(*o.ray_cast(centre - 10 * box_y, box_y, 100), 9.0, 1e-9);
  // A ray along north through the centre enters through the long side: it
  // meets |y_box| = 1 at a north offset of sqrt(2) before the centre.
  EXPECT_NEAR(*o.ray_cast(Vec3(-5, 5, -2), unit(1, 0, 0), 100), 10.0 - std::sqrt(2.0), 1e-9);
  // Alongside the long side, inside the box's north-east bounds but beside it.
  EXPECT_FALSE(o.ray_cast(centre + 1.2 * box_y - 10 * box_x, box_x, 100));
  EXPECT_NEAR(*o.ray_cast(centre + 0.8 * box_y - 10 * box_x, box_x, 100), 8.0, 1e-9);
  // Bounds cover the rotated footprint: half-extent (4 + 2) / 2 * cos 45.
  EXPECT_NEAR(o.bounds_max().x() - 5, 3 * std::sqrt(0.5), 1e-9);
  EXPECT_NEAR(o.bounds_min().z(), -5, 1e-12);
  EXPECT_NEAR(o.bounds_max().z(), 0, 1e-12);
}

TEST(WorldBox, RayCastAgreesWithDistanceForRandomRays) {
  expect_ray_cast_agrees_with_distance(Obstacle(box(1, 3, -2, 4, 2, 5, 0)), 1);
  expect_ray_cast_agrees_with_distance(Obstacle(box(1, 3, -2, 4, 2, 5, 45)), 2);
  expect_ray_cast_agrees_with_distance(Obstacle(box(1, 3, -2, 6, 1.5, 3, -20), 4.0), 3);
}

TEST(WorldBox, DistanceMatchesSurfaceSampling) {
  for (double yaw : {0.0, 45.0, 110.0}) {
    const ObstacleSpec s = box(1, 3, -2, 4, 2, 5, yaw);
    const Obstacle o(s);
    const auto surface = box_surface(s, 0.0, 0.05);
    for (const Vec3& p : points_around(o, 100, 7)) {
      const double d = o.distance(p);
      const double sampled = brute_force_distance(surface, p);
      EXPECT_LE(d, sampled + 1e-9);
      EXPECT_NEAR(d, sampled, 0.04) << "yaw " << yaw << " p " << p.transpose();
    }
  }
}

TEST(WorldCylinder, SideAndTopCapHitsAreAnalytic) {
  // Radius 2, 6 m tall, centred at (10, 0).
  const Obstacle o(cylinder(1, 10, 0, 4, 6));
  EXPECT_NEAR(*o.ray_cast(Vec3(0, 0, -3), unit(1, 0, 0), 100), 8.0, 1e-12);
  // Off-axis chord: offset 1 from the axis meets the side at sqrt(4 - 1) before it.
  EXPECT_NEAR(*o.ray_cast(Vec3(0, 1, -3), unit(1, 0, 0), 100), 10.0 - std::sqrt(3.0), 1e-12);
  EXPECT_FALSE(o.ray_cast(Vec3(0, 2.001, -3), unit(1, 0, 0), 100));
  // Top cap from straight above and at a slant onto the cap.
  EXPECT_NEAR(*o.ray_cast(Vec3(10.5, 0.5, -20), unit(0, 0, 1), 100), 14.0, 1e-12);
  const Vec3 slant = unit(1, 0, 1);  // 45 deg down towards north
  EXPECT_NEAR(*o.ray_cast(Vec3(7, 0, -10), slant, 100), 4.0 * std::sqrt(2.0), 1e-9);
  // Over the top.
  EXPECT_FALSE(o.ray_cast(Vec3(0, 0, -6.001), unit(1, 0, 0), 100));
  EXPECT_NEAR(o.bounds_min().x(), 8, 1e-12);
  EXPECT_NEAR(o.bounds_max().y(), 2, 1e-12);
}

TEST(WorldCylinder, RayCastAndDistanceAgreeWithIndependentChecks) {
  const ObstacleSpec s = cylinder(1, 3, -2, 3, 5);
  const Obstacle o(s);
  expect_ray_cast_agrees_with_distance(o, 11);
  const auto surface = cylinder_surface(3, -2, 1.5, -5, 0, 0.04);
  for (const Vec3& p : points_around(o, 100, 12)) {
    const double sampled = brute_force_distance(surface, p);
    EXPECT_NEAR(o.distance(p), sampled, 0.04) << p.transpose();
  }
}

TEST(WorldGround, OnlyDownwardRaysHitTheGround) {
  const World w({}, 5.0);  // ground at altitude 5: z = -5
  const auto down = w.ray_cast(Vec3(0, 0, -30), unit(1, 0, 1), 100);
  ASSERT_TRUE(down);
  EXPECT_NEAR(down->range, 25 * std::sqrt(2.0), 1e-9);
  EXPECT_EQ(down->obstacle_id, 0);
  EXPECT_FALSE(w.ray_cast(Vec3(0, 0, -30), unit(1, 0, -1), 1000));
  EXPECT_FALSE(w.ray_cast(Vec3(0, 0, -30), unit(1, 0, 0), 1000));
  EXPECT_FALSE(w.ray_cast(Vec3(0, 0, -30), unit(1, 0, 1), 35));
  EXPECT_TRUE(std::isinf(w.distance_to_obstacles(Vec3(0, 0, -30))));
}

TEST(WorldGround, DistanceToTheGroundIsTheHeightAboveIt) {
  World w({}, 5.0);  // ground at altitude 5: z = -5
  EXPECT_NEAR(w.distance_to_ground(Vec3(3, 4, -30)), 25.0, 1e-12);
  EXPECT_DOUBLE_EQ(w.distance_to_ground(Vec3(0, 0, -5)), 0.0);
  EXPECT_DOUBLE_EQ(w.distance_to_ground(Vec3(0, 0, 2)), 0.0);  // below the surface
  w.set_ground_altitude(-10.0);
  EXPECT_NEAR(w.distance_to_ground(Vec3(3, 4, -30)), 40.0, 1e-12);
}

TEST(WorldGround, ObstaclesStandOnTheGroundAndMoveWithIt) {
  World w({box(3, 10, 0, 2, 2, 5)}, 10.0);
  EXPECT_NEAR(w.obstacles()[0].bounds_min().z(), -15.0, 1e-12);
  auto hit = w.ray_cast(Vec3(10, 0, -40), unit(0, 0, 1), 100);
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->range, 25.0, 1e-12);
  EXPECT_EQ(hit->obstacle_id, 3);
  w.set_ground_altitude(0.0);
  hit = w.ray_cast(Vec3(10, 0, -40), unit(0, 0, 1), 100);
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->range, 35.0, 1e-12);
  // Beside the box the same ray reaches the ground.
  hit = w.ray_cast(Vec3(20, 0, -40), unit(0, 0, 1), 100);
  ASSERT_TRUE(hit);
  EXPECT_EQ(hit->obstacle_id, 0);
  EXPECT_NEAR(hit->range, 40.0, 1e-12);
}

TEST(WorldRayCast, OriginInsideGivesZero) {
  const Vec3 dir = unit(1, 0.3, 0.1);
  EXPECT_DOUBLE_EQ(*Obstacle(box(1, 0, 0, 4, 2, 5, 30)).ray_cast(Vec3(0.2, 0.1, -1), dir, 50), 0);
  EXPECT_DOUBLE_EQ(*Obstacle(cylinder(1, 0, 0, 4, 5)).ray_cast(Vec3(0.2, 0.1, -1), dir, 50), 0);
  const Obstacle t(tree(1, 0, 0, 8, 6, 12, 3));
  EXPECT_DOUBLE_EQ(*t.ray_cast(Vec3(0, 0, -1), dir, 50), 0);  // in the trunk
  const CanopyBlob& blob = t.canopy().front();
  EXPECT_DOUBLE_EQ(*t.ray_cast(blob.centre, dir, 50), 0);
  const World w({box(7, 0, 0, 4, 2, 5)});
  const auto hit = w.ray_cast(Vec3(0, 0, -1), dir, 50);
  ASSERT_TRUE(hit);
  EXPECT_DOUBLE_EQ(hit->range, 0);
  EXPECT_EQ(hit->obstacle_id, 7);
  EXPECT_DOUBLE_EQ(w.distance_to_obstacles(Vec3(0, 0, -1)), 0);
}

/// Direct sphere intersection for comparison.
std::optional<double> sphere_hit(const Vec3& centre, double radius, const Vec3& o, const Vec3& d) {
  const Vec3 oc = o - centre;
  const double b = oc.dot(d), c = oc.squaredNorm() - radius * radius;
  const double disc = b * b - c;
  if (disc < 0) return std::nullopt;
  const double t = -b - std::sqrt(disc);
  if (t < 0) return std::nullopt;
  return t;
}

TEST(WorldTree, CanopyRayCastIsTheNearestSphereHit) {
  const Obstacle t(tree(1, 20, 5, 10, 8, 15, 42));
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  int compared = 0;
  for (const CanopyBlob& aimed : t.canopy()) {
    for (int k = 0; k < 5; ++k) {
      // From outside the tree, at canopy height, towards this sphere.
      const Vec3 origin(20 + 30 * u(rng), 5 + 30 * u(rng), -9 + 3 * u(rng));
      if (t.contains(origin)) continue;
      const Vec3 dir =
          (aimed.centre + 0.5 * aimed.radius * Vec3(u(rng), u(rng), u(rng)) - origin).normalized();
      std::optional<double> expected;
      for (const CanopyBlob& b : t.canopy()) {
        const auto h = sphere_hit(b.centre, b.radius, origin, dir);
        if (h && (!expected || *h < *expected)) expected = h;
      }
      ASSERT_TRUE(expected);
      const auto cast = t.ray_cast(origin, dir, 200);
      ASSERT_TRUE(cast);
      // The trunk can only come first; it does not reach canopy height here.
      if (origin.z() < -0.45 * 15 && dir.z() < 0) {
        EXPECT_NEAR(*cast, *expected, 1e-9);
      }
      EXPECT_LE(*cast, *expected + 1e-9);
      ++compared;
    }
  }
  EXPECT_GT(compared, 40);
}

TEST(WorldTree, TrunkIsHitBelowTheCanopy) {
  const Obstacle t(tree(1, 20, 5, 10, 8, 15, 42));
  EXPECT_NEAR(t.trunk_radius(), std::max(0.3, 0.06 * 8), 1e-12);
  EXPECT_NEAR(t.trunk_top_altitude(), 0.45 * 15, 1e-12);
  // At 1 m above the ground the canopy is far above: only the trunk.
  EXPECT_NEAR(*t.ray_cast(Vec3(0, 5, -1), unit(1, 0, 0), 100), 20 - t.trunk_radius(), 1e-9);
}

TEST(WorldTree, RayCastAndDistanceAgreeWithIndependentChecks) {
  const ObstacleSpec s = tree(1, 0, 0, 7, 9, 12, 8);
  const Obstacle o(s);
  expect_ray_cast_agrees_with_distance(o, 21);
  std::vector<Vec3> surface =
      cylinder_surface(0, 0, o.trunk_radius(), -o.trunk_top_altitude(), 0, 0.05);
  for (const CanopyBlob& b : o.canopy()) {
    const int count = static_cast<int>(4 * kPi * b.radius * b.radius / (0.05 * 0.05)) + 100;
    const auto part = sphere_surface(b.centre, b.radius, count);
    surface.insert(surface.end(), part.begin(), part.end());
  }
  for (const Vec3& p : points_around(o, 100, 22))
    EXPECT_NEAR(o.distance(p), brute_force_distance(surface, p), 0.06) << p.transpose();
}

TEST(WorldTree, CanopyIsDeterministicPerSeedAndDiffersBetweenSeeds) {
  const Obstacle a(tree(1, 0, 0, 10, 8, 15, 42));
  const Obstacle b(tree(2, 0, 0, 10, 8, 15, 42));
  const Obstacle c(tree(3, 0, 0, 10, 8, 15, 43));
  ASSERT_EQ(a.canopy().size(), b.canopy().size());
  for (size_t i = 0; i < a.canopy().size(); ++i) {
    EXPECT_EQ(a.canopy()[i].centre, b.canopy()[i].centre);
    EXPECT_EQ(a.canopy()[i].radius, b.canopy()[i].radius);
  }
  bool differs = a.canopy().size() != c.canopy().size();
  for (size_t i = 0; !differs && i < a.canopy().size(); ++i)
    differs = (a.canopy()[i].centre - c.canopy()[i].centre).norm() > 1e-3;
  EXPECT_TRUE(differs);
}

TEST(WorldTree, CanopyFillsItsEnvelopeWithTheTopAtTheHeight) {
  for (int seed = 0; seed < 30; ++seed) {
    for (const auto& [length, width, height] :
         std::vector<std::array<double, 3>>{{10, 8, 15}, {6, 12, 9}, {3, 3, 20}}) {
      const Obstacle t(tree(1, 4, -3, length, width, height, seed), 2.0);
      const auto& blobs = t.canopy();
      ASSERT_GE(blobs.size(), 12u);
      ASSERT_LE(blobs.size(), 20u);
      Vec3 lo = Vec3::Constant(1e9), hi = Vec3::Constant(-1e9);
      double smallest = 1e9, largest = 0;
      for (const auto& b : blobs) {
        lo = lo.cwiseMin(b.centre - Vec3::Constant(b.radius));
        hi = hi.cwiseMax(b.centre + Vec3::Constant(b.radius));
        smallest = std::min(smallest, b.radius);
        largest = std::max(largest, b.radius);
      }
      // Top at the height above the ground (altitude 2 here).
      EXPECT_NEAR(-lo.z(), 2.0 + height, 1e-9) << "seed " << seed;
      EXPECT_NEAR(hi.x() - lo.x(), length, 0.1 * length) << "seed " << seed;
      EXPECT_NEAR(hi.y() - lo.y(), width, 0.1 * width) << "seed " << seed;
      EXPECT_GE(-hi.z(), 2.0 + 0.3 * height);  // the canopy stays in the upper part
      EXPECT_GT(largest, 1.3 * smallest);      // varied radii
      // Every sphere lies within the envelope ellipsoid (a small tolerance
      // for the shift that puts the top at the height).
      const Vec3 semi(0.5 * length, 0.5 * width, 0.325 * height);
      const Vec3 centre(4, -3, -2.0 - 0.675 * height);
      for (const auto& b : blobs)
        for (const Vec3& p : sphere_surface(b.centre, b.radius, 200))
          EXPECT_LE((p - centre).cwiseQuotient(semi).norm(), 1.02) << "seed " << seed;
    }
  }
}

TEST(WorldTree, CanopyLooksRaggedToHorizontalRays) {
  const Obstacle t(tree(1, 0, 0, 10, 10, 15, 7));
  // From 20 m out, towards the axis at several canopy heights and azimuths:
  // a smooth solid would give a handful of ranges, the blobs give many.
  std::vector<double> ranges;
  for (int az = 0; az < 36; ++az)
    for (double altitude : {8.0, 10.0, 12.0}) {
      const double a = deg2rad(10.0 * az);
      const Vec3 origin(20 * std::cos(a), 20 * std::sin(a), -altitude);
      const auto r = t.ray_cast(origin, -Vec3(std::cos(a), std::sin(a), 0), 40);
      if (r) ranges.push_back(*r);
    }
  ASSERT_GT(ranges.size(), 80u);
  const auto [mn, mx] = std::minmax_element(ranges.begin(), ranges.end());
  EXPECT_GT(*mx - *mn, 1.0);
  std::sort(ranges.begin(), ranges.end());
  const auto distinct = std::unique(ranges.begin(), ranges.end(),
                                    [](double x, double y) { return std::abs(x - y) < 0.01; }) -
                        ranges.begin();
  EXPECT_GT(distinct, 40);
}

TEST(WorldSchedule, PopUpObstaclesCountOnlyWhilePresent) {
  ObstacleSpec s = box(9, 10, 0, 2, 2, 50);
  s.appear_time = 10;
  s.disappear_time = 20;
  const World w({s});
  const Obstacle& o = w.obstacles()[0];
  EXPECT_FALSE(o.present_at(5));
  EXPECT_TRUE(o.present_at(10));
  EXPECT_TRUE(o.present_at(15));
  EXPECT_FALSE(o.present_at(20));
  const Vec3 origin(0, 0, -2), dir = unit(1, 0, 0);
  EXPECT_FALSE(w.ray_cast(origin, dir, 100, 5.0));
  ASSERT_TRUE(w.ray_cast(origin, dir, 100, 15.0));
  EXPECT_EQ(w.ray_cast(origin, dir, 100, 15.0)->obstacle_id, 9);
  EXPECT_FALSE(w.ray_cast(origin, dir, 100, 25.0));
  EXPECT_TRUE(w.ray_cast(origin, dir, 100, -1.0));  // negative time: every obstacle
  EXPECT_TRUE(std::isinf(w.distance_to_obstacles(origin, 5.0)));
  EXPECT_NEAR(w.distance_to_obstacles(origin, 15.0), 9.0, 1e-12);

  ObstacleSpec always = box(1, 0, 0, 1, 1, 1);
  EXPECT_TRUE(Obstacle(always).present_at(0));
  EXPECT_TRUE(Obstacle(always).present_at(1e6));
}

TEST(WorldRayCast, NearestOfManyObstaclesWins) {
  std::vector<ObstacleSpec> specs;
  for (int i = 0; i < 50; ++i) specs.push_back(cylinder(i + 1, 10 + 5 * i, 0, 2, 10));
  specs.push_back(box(100, 7, 0, 1, 4, 3));  // short box in front of the first post
  const World w(specs);
  auto hit = w.ray_cast(Vec3(0, 0, -2), unit(1, 0, 0), 500);
  ASSERT_TRUE(hit);
  EXPECT_EQ(hit->obstacle_id, 100);
  EXPECT_NEAR(hit->range, 6.5, 1e-12);
  hit = w.ray_cast(Vec3(0, 0, -5), unit(1, 0, 0), 500);  // over the box
  ASSERT_TRUE(hit);
  EXPECT_EQ(hit->obstacle_id, 1);
  EXPECT_NEAR(hit->range, 9.0, 1e-12);
  EXPECT_NEAR(w.distance_to_obstacles(Vec3(252.5, 0, -5)), 2.5 - 1.0, 1e-9);
}

TEST(WorldRayCast, ReplacingTheObstacleSetRemovesAndMovesObstacles) {
  World w({box(1, 10, 0, 2, 2, 5), tree(2, 30, 0, 6, 6, 10, 4)});
  const Vec3 origin(0, 0, -2), north = unit(1, 0, 0);
  EXPECT_EQ(w.ray_cast(origin, north, 100)->obstacle_id, 1);
  const auto canopy = w.obstacles()[1].canopy();
  // The box is gone, the tree unchanged.
  w.set_obstacles({tree(2, 30, 0, 6, 6, 10, 4)});
  ASSERT_EQ(w.obstacles().size(), 1u);
  EXPECT_EQ(w.ray_cast(origin, north, 100)->obstacle_id, 2);
  EXPECT_EQ(w.obstacles()[0].canopy()[0].centre, canopy[0].centre);
  // The tree moved east out of the way.
  w.set_obstacles({tree(2, 30, 20, 6, 6, 10, 4)});
  EXPECT_FALSE(w.ray_cast(origin, north, 100));
  EXPECT_NEAR(w.obstacles()[0].canopy()[0].centre.y() - canopy[0].centre.y(), 20.0, 1e-9);
}

}  // namespace
}  // namespace ofn::world
