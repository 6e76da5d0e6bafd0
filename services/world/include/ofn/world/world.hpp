#pragma once
// The simulated world: flat ground plus the course's obstacles (boxes with a
// yaw, vertical cylinders, trees with a trunk and a ragged seeded canopy).
// Ground truth for the LIDAR head's ray casting, the obstacle injector's
// pop-up schedule and the flight report's true clearance. No LCM in here.

#include <optional>
#include <vector>

#include "ofn/common/frames.hpp"
#include "ofn/common/scenario.hpp"

namespace ofn::world {

/// A sphere of a tree canopy, world NED.
struct CanopyBlob {
  Vec3 centre;
  double radius = 0;
};

/// One obstacle with its geometry expanded for fast queries.
class Obstacle {
 public:
  /// ground_altitude: altitude of the ground the obstacle stands on.
  explicit Obstacle(const ObstacleSpec& spec, double ground_altitude = 0.0);

  const ObstacleSpec& spec() const { return spec_; }
  /// Present at time t (s after the start), honouring appear/disappear times.
  bool present_at(double t) const { return spec_.present_at(t); }

  /// Distance along the unit ray to the first surface point at or beyond
  /// the origin (0 when the origin is inside), if within max_range.
  std::optional<double> ray_cast(const Vec3& origin, const Vec3& unit_dir, double max_range) const;
  /// Euclidean distance from p to the obstacle (0 inside), ground_altitude
  /// being the altitude of the obstacle's base.
  double distance(const Vec3& p) const;
  bool contains(const Vec3& p) const { return distance(p) <= 0.0; }

  /// Axis-aligned world bounds (NED): min and max corner.
  Vec3 bounds_min() const { return bounds_min_; }
  Vec3 bounds_max() const { return bounds_max_; }
  /// The canopy spheres of a tree (empty for other kinds).
  const std::vector<CanopyBlob>& canopy() const { return canopy_; }
  double trunk_radius() const { return trunk_radius_; }
  /// Altitude of the top of a tree's trunk (0 for other kinds).
  double trunk_top_altitude() const { return trunk_top_altitude_; }

 private:
  ObstacleSpec spec_;
  double ground_z_ = 0;
  Vec3 bounds_min_, bounds_max_;
  std::vector<CanopyBlob> canopy_;
  double trunk_radius_ = 0;
  double trunk_top_altitude_ = 0;
};

/// What a ray hit.
struct RayHit {
  double range = 0;
  int obstacle_id = 0;  // 0: the ground
};

class World {
 public:
  World() = default;
  explicit World(const std::vector<ObstacleSpec>& specs, double ground_altitude = 0.0);

  /// Replaces the obstacle set (e.g. from VIRTUAL_OBSTACLES).
  void set_obstacles(const std::vector<ObstacleSpec>& specs);
  /// Moves the ground and the obstacles standing on it.
  void set_ground_altitude(double altitude);
  double ground_altitude() const { return ground_altitude_; }
  const std::vector<Obstacle>& obstacles() const { return obstacles_; }

  /// First hit of the ray against the ground and every obstacle, within
  /// max_range. Only obstacles present at time t count (t < 0: all).
  std::optional<RayHit> ray_cast(const Vec3& origin, const Vec3& unit_dir, double max_range,
                                 double t = -1.0) const;
  /// Distance from p to the nearest obstacle surface (not the ground);
  /// +infinity with no obstacles. 0 inside an obstacle.
  double distance_to_obstacles(const Vec3& p, double t = -1.0) const;
  /// Height of p above the flat ground; 0 at or below it.
  double distance_to_ground(const Vec3& p) const;

 private:
  std::vector<ObstacleSpec> specs_;
  std::vector<Obstacle> obstacles_;
  double ground_altitude_ = 0;
};

}  // namespace ofn::world
