#include "ofn/world/world.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <unordered_map>

namespace ofn::world {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kParallel = 1e-12;

// Tree proportions: the trunk reaches into the canopy, whose envelope spans
// the upper part of the height.
constexpr double kTrunkRadiusFraction = 0.06;  // of the smaller canopy extent
constexpr double kMinTrunkRadius = 0.3;        // m
constexpr double kTrunkTopFraction = 0.45;     // of the height
constexpr double kCanopyBottomFraction = 0.35;
// Anchor spheres touch the envelope just inside it, so that sampling error in
// the containment test cannot push them out.
constexpr double kAnchorInset = 0.995;

/// A parameter interval [enter, exit] along a ray, narrowed by each shape
/// constraint; empty when exit < enter.
struct Interval {
  double enter = -kInf;
  double exit = kInf;

  /// Narrows to the slab lo <= origin + t dir <= hi of one axis.
  bool clip_slab(double origin, double dir, double lo, double hi) {
    if (std::abs(dir) < kParallel) return origin >= lo && origin <= hi;
    double t0 = (lo - origin) / dir;
    double t1 = (hi - origin) / dir;
    if (t0 > t1) std::swap(t0, t1);
    enter = std::max(enter, t0);
    exit = std::min(exit, t1);
    return enter <= exit;
  }

  /// The ray contract: first point at t >= 0 (0 when the origin is inside).
  std::optional<double> first_hit(double max_range) const {
    if (exit < enter || exit < 0.0) return std::nullopt;
    const double t = std::max(enter, 0.0);
    if (t > max_range) return std::nullopt;
    return t;
  }
};

bool hits_aabb(const Vec3& lo, const Vec3& hi, const Vec3& origin, const Vec3& dir,
               double max_range) {
  Interval iv;
  for (int i = 0; i < 3; ++i)
    if (!iv.clip_slab(origin[i], dir[i], lo[i], hi[i])) return false;
  return iv.first_hit(max_range).has_value();
}

double aabb_distance(const Vec3& lo, const Vec3& hi, const Vec3& p) {
  const Vec3 outside = (lo - p).cwiseMax(p - hi).cwiseMax(0.0);
  return outside.norm();
}

/// Vertical cylinder around (north, east) from z_top up to z_bottom (NED, so
/// z_top < z_bottom).
std::optional<double> ray_cast_cylinder(double north, double east, double radius, double z_top,
                                        double z_bottom, const Vec3& origin, const Vec3& dir,
                                        double max_range) {
  Interval iv;
  if (!iv.clip_slab(origin.z(), dir.z(), z_top, z_bottom)) return std::nullopt;
  const double ox = origin.x() - north, oy = origin.y() - east;
  const double a = dir.x() * dir.x() + dir.y() * dir.y();
  const double c = ox * ox + oy * oy - radius * radius;
  if (a < kParallel) {
    if (c > 0) return std::nullopt;
  } else {
    const double b = ox * dir.x() + oy * dir.y();
    const double disc = b * b - a * c;
    if (disc < 0) return std::nullopt;
    const double root = std::sqrt(disc);
    iv.enter = std::max(iv.enter, (-b - root) / a);
    iv.exit = std::min(iv.exit, (-b + root) / a);
  }
  return iv.first_hit(max_range);
}

double cylinder_distance(double north, double east, double radius, double z_top, double z_bottom,
                         const Vec3& p) {
  const double radial = std::max(std::hypot(p.x() - north, p.y() - east) - radius, 0.0);
  const double vertical = std::max({z_top - p.z(), p.z() - z_bottom, 0.0});
  return std::hypot(radial, vertical);
}

std::optional<double> ray_cast_sphere(const Vec3& centre, double radius, const Vec3& origin,
                                      const Vec3& dir, double max_range) {
  const Vec3 oc = origin - centre;
  const double c = oc.squaredNorm() - radius * radius;
  if (c <= 0) return 0.0;
  const double b = oc.dot(dir);
  if (b >= 0) return std::nullopt;  // outside and heading away
  const double disc = b * b - c;
  if (disc < 0) return std::nullopt;
  const double t = -b - std::sqrt(disc);
  if (t > max_range) return std::nullopt;
  return t;
}

bool same_spec(const ObstacleSpec& a, const ObstacleSpec& b) {
  return a.kind == b.kind && a.id == b.id && a.north == b.north && a.east == b.east &&
         a.length == b.length && a.width == b.width && a.height == b.height && a.yaw == b.yaw &&
         a.seed == b.seed && a.appear_time == b.appear_time && a.disappear_time == b.disappear_time;
}

void keep_nearest(std::optional<double>& best, std::optional<double> candidate) {
  if (candidate && (!best || *candidate < *best)) best = candidate;
}

/// Evenly spread unit directions (Fibonacci sphere), for the containment test.
const std::vector<Vec3>& sphere_directions() {
  static const std::vector<Vec3> directions = [] {
    constexpr int kCount = 256;
    const double golden = kPi * (3.0 - std::sqrt(5.0));
    std::vector<Vec3> d;
    d.reserve(kCount);
    for (int i = 0; i < kCount; ++i) {
      const double z = 1.0 - 2.0 * (i + 0.5) / kCount;
      const double r = std::sqrt(1.0 - z * z);
      d.emplace_back(r * std::cos(golden * i), r * std::sin(golden * i), z);
    }
    // The six axis directions make the extreme points of every sphere exact.
    for (int axis = 0; axis < 3; ++axis) {
      d.push_back(Vec3::Unit(axis));
      d.push_back(-Vec3::Unit(axis));
    }
    return d;
  }();
  return directions;
}

/// Canopy generation in the frame of the envelope ellipsoid (centred, NED
/// axes, semi-axes `axes`).
class CanopyBuilder {
 public:
  CanopyBuilder(const Vec3& axes, int seed) : axes_(axes), rng_(static_cast<uint32_t>(seed)) {}

  /// Uniform in [0, 1); computed from the raw generator output so that a
  /// seed gives the same tree with every standard library.
  double uniform() { return static_cast<double>(rng_()) / 4294967296.0; }
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  uint32_t raw() { return rng_(); }

  double envelope_measure(const Vec3& p) const { return p.cwiseQuotient(axes_).squaredNorm(); }

  bool fits(const Vec3& centre, double radius) const {
    for (const Vec3& d : sphere_directions())
      if (envelope_measure(centre + radius * d) > 1.0) return false;
    return true;
  }

  /// Largest radius (within the smallest semi-axis) for which the sphere
  /// centre_of(r) fits; centre_of must give nested spheres as r grows.
  template <class CentreOf>
  double largest_fitting_radius(CentreOf centre_of) const {
    double lo = 0.0, hi = axes_.minCoeff();
    if (fits(centre_of(hi), hi)) return hi;
    for (int i = 0; i < 20; ++i) {
      const double mid = 0.5 * (lo + hi);
      (fits(centre_of(mid), mid) ? lo : hi) = mid;
    }
    return lo;
  }

  /// A sphere tangent to the envelope from inside at the point in the
  /// normalised direction `e`; radius a random share of the largest that fits.
  CanopyBlob anchor(const Vec3& e) {
    const Vec3 touch = kAnchorInset * e.cwiseProduct(axes_);
    const Vec3 inward = -touch.cwiseQuotient(axes_.cwiseProduct(axes_)).normalized();
    const double largest =
        largest_fitting_radius([&](double r) -> Vec3 { return touch + r * inward; });
    const double r = largest * uniform(0.6, 1.0);
    return {touch + r * inward, r};
  }

  /// A sphere in the largest gap the spheres so far leave in the envelope:
  /// the best of a few random centres, each scored by how far it is from
  /// the spheres so far and (a lower bound of) how far from the envelope.
  CanopyBlob filler(const std::vector<CanopyBlob>& so_far) {
    constexpr int kCandidates = 24;
    Vec3 best_centre = Vec3::Zero();
    double best_score = -kInf;
    for (int i = 0; i < kCandidates; ++i) {
      Vec3 u;
      do {
        u = Vec3(uniform(-1, 1), uniform(-1, 1), uniform(-1, 1));
      } while (u.norm() > 0.9);
      const Vec3 centre = u.cwiseProduct(axes_);
      double gap = kInf;
      for (const auto& b : so_far) gap = std::min(gap, (centre - b.centre).norm() - b.radius);
      const double score = std::min(gap, (1.0 - u.norm()) * axes_.minCoeff());
      if (score > best_score) {
        best_score = score;
        best_centre = centre;
      }
    }
    const double largest = largest_fitting_radius([&](double) { return best_centre; });
    return {best_centre, largest * uniform(0.75, 1.0)};
  }

 private:
  Vec3 axes_;
  std::mt19937 rng_;
};

}  // namespace

Obstacle::Obstacle(const ObstacleSpec& spec, double ground_altitude)
    : spec_(spec), ground_z_(-ground_altitude) {
  const double length = std::max(spec_.length, 1e-6);
  const double width = std::max(spec_.width, 1e-6);
  const double height = std::max(spec_.height, 1e-6);
  const double top_z = ground_z_ - height;
  switch (spec_.kind) {
    case ObstacleSpec::Kind::kBox: {
      const double c = std::abs(std::cos(spec_.yaw)), s = std::abs(std::sin(spec_.yaw));
      const double half_north = 0.5 * (c * length + s * width);
      const double half_east = 0.5 * (s * length + c * width);
      bounds_min_ = Vec3(spec_.north - half_north, spec_.east - half_east, top_z);
      bounds_max_ = Vec3(spec_.north + half_north, spec_.east + half_east, ground_z_);
      break;
    }
    case ObstacleSpec::Kind::kCylinder: {
      const double r = 0.5 * length;
      bounds_min_ = Vec3(spec_.north - r, spec_.east - r, top_z);
      bounds_max_ = Vec3(spec_.north + r, spec_.east + r, ground_z_);
      break;
    }
    case ObstacleSpec::Kind::kTree: {
      const double smaller = std::min(length, width);
      trunk_radius_ =
          std::min(std::max(kTrunkRadiusFraction * smaller, kMinTrunkRadius), 0.5 * smaller);
      trunk_top_altitude_ = ground_altitude + kTrunkTopFraction * height;

      const double canopy_half_height = 0.5 * (1.0 - kCanopyBottomFraction) * height;
      const Vec3 envelope_centre(spec_.north, spec_.east, top_z + canopy_half_height);
      CanopyBuilder builder(Vec3(0.5 * length, 0.5 * width, canopy_half_height), spec_.seed);
      const int count = 12 + static_cast<int>(builder.raw() % 9);
      std::vector<CanopyBlob> blobs;
      // The crown's top, then its four horizontal extremes, each a little off
      // the axes so that no two trees look alike; fillers make it ragged.
      blobs.push_back(builder.anchor(
          Vec3(builder.uniform(-0.05, 0.05), builder.uniform(-0.05, 0.05), -1.0).normalized()));
      for (int side = 0; side < 4; ++side) {
        const double azimuth = side * 0.5 * kPi + deg2rad(builder.uniform(-10, 10));
        const double z = builder.uniform(-0.15, 0.15);
        const double horizontal = std::sqrt(1.0 - z * z);
        blobs.push_back(builder.anchor(
            Vec3(horizontal * std::cos(azimuth), horizontal * std::sin(azimuth), z)));
      }
      while (static_cast<int>(blobs.size()) < count) blobs.push_back(builder.filler(blobs));

      // The crown's top is the tree's height exactly.
      double crown_top = kInf;
      for (const auto& b : blobs) crown_top = std::min(crown_top, b.centre.z() - b.radius);
      const Vec3 shift = envelope_centre + Vec3(0, 0, -canopy_half_height - crown_top);
      bounds_min_ = Vec3(spec_.north - trunk_radius_, spec_.east - trunk_radius_, top_z);
      bounds_max_ = Vec3(spec_.north + trunk_radius_, spec_.east + trunk_radius_, ground_z_);
      for (auto& b : blobs) {
        b.centre += shift;
        bounds_min_ = bounds_min_.cwiseMin(b.centre - Vec3::Constant(b.radius));
        bounds_max_ = bounds_max_.cwiseMax(b.centre + Vec3::Constant(b.radius));
      }
      canopy_ = std::move(blobs);
      break;
    }
  }
}

std::optional<double> Obstacle::ray_cast(const Vec3& origin, const Vec3& unit_dir,
                                         double max_range) const {
  if (!hits_aabb(bounds_min_, bounds_max_, origin, unit_dir, max_range)) return std::nullopt;
  const double top_z = ground_z_ - spec_.height;
  switch (spec_.kind) {
    case ObstacleSpec::Kind::kBox: {
      // Slabs in the box frame: x along the box's length, y along its width.
      const double c = std::cos(spec_.yaw), s = std::sin(spec_.yaw);
      const double rel_n = origin.x() - spec_.north, rel_e = origin.y() - spec_.east;
      Interval iv;
      if (!iv.clip_slab(c * rel_n + s * rel_e, c * unit_dir.x() + s * unit_dir.y(),
                        -0.5 * spec_.length, 0.5 * spec_.length) ||
          !iv.clip_slab(-s * rel_n + c * rel_e, -s * unit_dir.x() + c * unit_dir.y(),
                        -0.5 * spec_.width, 0.5 * spec_.width) ||
          !iv.clip_slab(origin.z(), unit_dir.z(), top_z, ground_z_))
        return std::nullopt;
      return iv.first_hit(max_range);
    }
    case ObstacleSpec::Kind::kCylinder:
      return ray_cast_cylinder(spec_.north, spec_.east, 0.5 * spec_.length, top_z, ground_z_,
                               origin, unit_dir, max_range);
    case ObstacleSpec::Kind::kTree: {
      std::optional<double> best =
          ray_cast_cylinder(spec_.north, spec_.east, trunk_radius_, -trunk_top_altitude_, ground_z_,
                            origin, unit_dir, max_range);
      for (const auto& blob : canopy_)
        keep_nearest(best, ray_cast_sphere(blob.centre, blob.radius, origin, unit_dir,
                                           best ? *best : max_range));
      return best;
    }
  }
  return std::nullopt;
}

double Obstacle::distance(const Vec3& p) const {
  const double top_z = ground_z_ - spec_.height;
  switch (spec_.kind) {
    case ObstacleSpec::Kind::kBox: {
      const double c = std::cos(spec_.yaw), s = std::sin(spec_.yaw);
      const double rel_n = p.x() - spec_.north, rel_e = p.y() - spec_.east;
      const Vec3 local(c * rel_n + s * rel_e, -s * rel_n + c * rel_e,
                       p.z() - 0.5 * (top_z + ground_z_));
      const Vec3 half(0.5 * spec_.length, 0.5 * spec_.width, 0.5 * spec_.height);
      return (local.cwiseAbs() - half).cwiseMax(0.0).norm();
    }
    case ObstacleSpec::Kind::kCylinder:
      return cylinder_distance(spec_.north, spec_.east, 0.5 * spec_.length, top_z, ground_z_, p);
    case ObstacleSpec::Kind::kTree: {
      double best = cylinder_distance(spec_.north, spec_.east, trunk_radius_, -trunk_top_altitude_,
                                      ground_z_, p);
      for (const auto& blob : canopy_)
        best = std::min(best, std::max((p - blob.centre).norm() - blob.radius, 0.0));
      return best;
    }
  }
  return kInf;
}

World::World(const std::vector<ObstacleSpec>& specs, double ground_altitude)
    : ground_altitude_(ground_altitude) {
  set_obstacles(specs);
}

void World::set_obstacles(const std::vector<ObstacleSpec>& specs) {
  // The injector resends the whole set; an unchanged obstacle keeps its
  // expanded geometry (a tree's canopy is the costly part).
  std::unordered_map<int, size_t> previous;
  for (size_t i = 0; i < obstacles_.size(); ++i) previous.emplace(obstacles_[i].spec().id, i);
  std::vector<Obstacle> rebuilt;
  rebuilt.reserve(specs.size());
  for (const auto& s : specs) {
    const auto it = previous.find(s.id);
    if (it != previous.end() && same_spec(obstacles_[it->second].spec(), s))
      rebuilt.push_back(obstacles_[it->second]);
    else
      rebuilt.emplace_back(s, ground_altitude_);
  }
  specs_ = specs;
  obstacles_ = std::move(rebuilt);
}

void World::set_ground_altitude(double altitude) {
  if (altitude == ground_altitude_) return;
  ground_altitude_ = altitude;
  obstacles_.clear();
  set_obstacles(std::vector<ObstacleSpec>(specs_));
}

std::optional<RayHit> World::ray_cast(const Vec3& origin, const Vec3& unit_dir, double max_range,
                                      double t) const {
  std::optional<RayHit> best;
  if (unit_dir.z() > kParallel) {
    const double range = std::max((-ground_altitude_ - origin.z()) / unit_dir.z(), 0.0);
    if (range <= max_range) best = RayHit{range, 0};
  }
  for (const auto& o : obstacles_) {
    if (t >= 0 && !o.present_at(t)) continue;
    const auto range = o.ray_cast(origin, unit_dir, best ? best->range : max_range);
    if (range && (!best || *range < best->range)) best = RayHit{*range, o.spec().id};
  }
  return best;
}

double World::distance_to_obstacles(const Vec3& p, double t) const {
  double best = kInf;
  for (const auto& o : obstacles_) {
    if (t >= 0 && !o.present_at(t)) continue;
    if (aabb_distance(o.bounds_min(), o.bounds_max(), p) >= best) continue;
    best = std::min(best, o.distance(p));
  }
  return best;
}

double World::distance_to_ground(const Vec3& p) const {
  return std::max(-p.z() - ground_altitude_, 0.0);
}

}  // namespace ofn::world
