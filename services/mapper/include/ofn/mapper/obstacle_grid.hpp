#pragma once
// The paper's vehicle-attached obstacle grid (section 3.1): a square grid,
// sized from the sensor range, that moves with the vehicle by whole cells.
// Every LIDAR hit is accumulated so that each cell keeps only its highest
// hit; hits are spread over a safety margin in the horizontal plane, and the
// result is smoothed by neighbour averaging for the optimiser's gradients.
//
// Filtering is conservative: a cell's filtered top is
//   max(inflated, mean of inflated over the (2r+1)^2 window),
// where inflated is the highest raw top within the safety-margin disc
// (cell-centre distance <= margin). The mean alone would lower an obstacle's
// edge cells; taking the max keeps every top at least as high as the hits
// that made it, and the averaging only adds a ramp on the free side of each
// edge, which gives the optimiser a gradient before it reaches the margin.
// Cells outside the grid count as free in the mean.

#include <cstdint>
#include <vector>

#include "ofn/common/frames.hpp"
#include "ofn/map/heightfield.hpp"

namespace ofn::mapping {

struct ObstacleGridConfig {
  double resolution = 1.0;        // m per cell
  double half_extent = 70.0;      // m from the vehicle to the grid edge (>= sensor range)
  double safety_margin = 0.5;     // m, horizontal inflation of every hit
  int smoothing_radius = 1;       // cells; neighbour averaging over (2r+1)^2, 0 = off
  double ground_altitude = 0;     // m, altitude of the flat ground
  double ground_clearance = 1.0;  // m; hits lower than this above the ground are ground
  double ceiling = 150.0;         // m above ground; hits above are clamped to it
};

class ObstacleGrid {
 public:
  /// The grid starts centred on (0, 0). Throws std::invalid_argument naming
  /// the first config field out of range.
  explicit ObstacleGrid(const ObstacleGridConfig& config);
  const ObstacleGridConfig& config() const { return config_; }

  /// Once the vehicle is a cell or more from the grid centre (along north or
  /// east), moves the grid by whole cells so that the vehicle is within half
  /// a cell of its centre, keeping cells that stay on the grid and clearing
  /// the ones that enter. Smaller offsets leave the grid where it is.
  void recentre(double vehicle_north, double vehicle_east);

  /// Accumulates hits (world NED, m). Returns how many landed on the grid as
  /// obstacle hits; ground hits, points off the grid and non-finite points
  /// are ignored and not counted.
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
  struct CellOffset {
    int rows;
    int cols;
  };
  void extend_bounds(int row, int col);
  void recompute_filtered();

  ObstacleGridConfig config_;
  // The origin moves by whole cells from where it started; keeping the count
  // instead of adding up metres keeps it on the same lattice forever.
  double initial_origin_north_ = 0;
  double initial_origin_east_ = 0;
  int64_t shifted_rows_ = 0;
  int64_t shifted_cols_ = 0;
  Heightfield raw_;
  Heightfield filtered_;
  bool dirty_ = true;
  std::vector<float> scratch_;           // inflated layer, then row-smoothed sums
  std::vector<float> inflated_;          // raw tops after margin inflation
  std::vector<CellOffset> margin_disc_;  // cells within the safety margin
  // Bounding box of nonzero raw cells (may be loose after lowering), so that
  // inflation and smoothing touch only the part of the grid that holds
  // obstacles; empty when row_lo_ > row_hi_.
  int row_lo_ = 0, row_hi_ = -1, col_lo_ = 0, col_hi_ = -1;
};

}  // namespace ofn::mapping
