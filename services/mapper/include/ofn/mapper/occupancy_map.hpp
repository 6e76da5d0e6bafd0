#pragma once
// 3-D probabilistic occupancy (OctoMap) with free space carved along every
// beam, so that a false return fades once later beams pass through it and an
// obstacle that was removed is forgotten. The mapper uses it to confirm or
// retire the grid's columns and to tell whether an obstacle's top was seen.

#include <cstdint>
#include <memory>
#include <vector>

#include "ofn/common/frames.hpp"

namespace octomap {
class OcTree;
}

namespace ofn::mapping {

struct OccupancyMapConfig {
  double resolution = 1.0;  // m, voxel edge
  double max_range = 61.0;  // m, beams are integrated up to this range
  double prob_hit = 0.7;
  double prob_miss = 0.4;
  double clamp_min = 0.12;
  double clamp_max = 0.97;
  double occupied_threshold = 0.5;
  double forget_radius = 150.0;  // m; voxels farther from the vehicle are pruned
  double ground_altitude = 0;    // m
};

class OccupancyMap {
 public:
  explicit OccupancyMap(const OccupancyMapConfig& config);
  ~OccupancyMap();
  OccupancyMap(const OccupancyMap&) = delete;
  OccupancyMap& operator=(const OccupancyMap&) = delete;

  /// Integrates one scan: hits end occupied, every beam (including the free
  /// rays that reached max range without a return) carves free space. Hits
  /// beyond max_range count as free rays cut at max_range. Within one scan
  /// each voxel is updated once, and a voxel holding a hit is not also
  /// carved. The tree's coordinates are world NED.
  void insert_scan(const Vec3& sensor_origin, const std::vector<Vec3>& hits,
                   const std::vector<Vec3>& free_ray_ends);

  /// Highest occupied voxel top (m above ground) in the vertical column
  /// around (north, east) of the given horizontal half size, searched
  /// between two altitudes (m above ground); negative when none. A voxel
  /// counts when its occupancy probability reaches min_probability (never
  /// less than the map's occupied threshold, which is the default). Voxels
  /// count when they overlap the column's interior: a bound lying exactly
  /// on a voxel face does not pull in the voxel beyond it. The returned top
  /// is the voxel's upper face, so it may exceed alt_hi by under a voxel.
  double column_top(double north, double east, double half_size, double alt_lo, double alt_hi,
                    double min_probability = 0.0) const;
  /// True when some voxel of the column within [alt_lo, alt_hi] (m above
  /// ground) is known free (has been crossed by a beam), i.e. the space
  /// above a top was seen.
  bool column_seen_free(double north, double east, double half_size, double alt_lo,
                        double alt_hi) const;

  /// Drops voxels farther than forget_radius (horizontally) from the vehicle.
  void forget_far(double vehicle_north, double vehicle_east);

  size_t num_nodes() const;
  size_t memory_bytes() const;
  const octomap::OcTree& tree() const { return *tree_; }

 private:
  struct ScanKeys;
  OccupancyMapConfig config_;
  std::unique_ptr<octomap::OcTree> tree_;
  std::unique_ptr<ScanKeys> scan_keys_;
};

}  // namespace ofn::mapping
