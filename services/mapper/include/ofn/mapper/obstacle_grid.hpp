#pragma once
// The paper's vehicle-attached obstacle grid (section 3.1): a square grid,
// sized from the sensor range, that moves with the vehicle by whole cells.
// Every LIDAR hit is accumulated so that each cell keeps only its highest
// hit; hits are spread over a safety margin in the horizontal plane, and the
// result is smoothed by neighbour averaging for the optimiser's gradients.

#include <cstdint>
#include <vector>

#include "ofn/common/frames.hpp"
#include "ofn/mapper/heightfield.hpp"

namespace ofn::mapping {

struct ObstacleGridConfig {
  double resolution = 1.0;      // m per cell
  double half_extent = 70.0;    // m from the vehicle to the grid edge (>= sensor range)
  double safety_margin = 1.5;   // m, horizontal inflation of every hit
  int smoothing_radius = 1;     // cells; neighbour averaging over (2r+1)^2, 0 = off
  double ground_altitude = 0;   // m, altitude of the flat ground
  double ground_clearance = 1.0;  // m; hits lower than this above the ground are ground
  double ceiling = 150.0;       // m above ground; hits above are clamped to it
};

class ObstacleGrid {
 public:
  explicit ObstacleGrid(const ObstacleGridConfig& config);
  const ObstacleGridConfig& config() const { return config_; }

  /// Moves the grid so that the vehicle is within half a cell of its centre,
  /// keeping cells that stay on the grid and clearing the ones that enter.
  void recentre(double vehicle_north, double vehicle_east);

  /// Accumulates hits (world NED, m). Returns how many landed on the grid.
  int64_t insert_hits(const std::vector<Vec3>& points);

  /// Lowers a cell's raw top (e.g. after the 3-D map proved the column free
  /// above `altitude`); 0 clears it. Cell indices of the raw layer.
  void lower_cell(int row, int col, float altitude);

  /// Highest hit per cell, no margin, no smoothing.
  const Heightfield& raw() const { return raw_; }
  /// Raw tops inflated by the margin and smoothed: what OBSTACLE_GRID carries
  /// and blob detection runs on. Recomputed lazily after changes.
  const Heightfield& filtered();

 private:
  ObstacleGridConfig config_;
  Heightfield raw_;
  Heightfield filtered_;
  bool dirty_ = true;
  std::vector<float> scratch_;
};

}  // namespace ofn::mapping
