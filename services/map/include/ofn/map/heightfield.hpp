#pragma once
// A 2.5-D obstacle map: for each square cell of a horizontal grid, the
// altitude (m above the ground) of the highest obstacle in it; 0 = free.
// The form OBSTACLE_GRID carries and the distance field is built from.

#include <cstddef>
#include <vector>

namespace ofn::mapping {

struct Heightfield {
  double origin_north = 0;  // m, world north of cell (0,0)'s lower corner
  double origin_east = 0;   // m, world east of cell (0,0)'s lower corner
  double resolution = 1.0;  // m per cell
  int rows = 0;             // cells along north
  int cols = 0;             // cells along east
  std::vector<float> top;   // rows * cols, row-major (row = north index)

  bool empty() const { return rows == 0 || cols == 0; }
  float& at(int row, int col) { return top[static_cast<size_t>(row) * cols + col]; }
  float at(int row, int col) const { return top[static_cast<size_t>(row) * cols + col]; }
  bool inside(int row, int col) const { return row >= 0 && row < rows && col >= 0 && col < cols; }
  /// Cell containing a world point (may lie outside the grid).
  int row_of(double north) const;
  int col_of(double east) const;
  double cell_centre_north(int row) const { return origin_north + (row + 0.5) * resolution; }
  double cell_centre_east(int col) const { return origin_east + (col + 0.5) * resolution; }
};

}  // namespace ofn::mapping
