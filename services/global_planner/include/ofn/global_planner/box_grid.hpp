#pragma once
// Axis-aligned boxes and a horizontal bucket grid over them: the geometry
// the global planner's segment tests run on. Pure core: world NED, metres.

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "ofn/common/frames.hpp"

namespace ofn::planning {

/// A closed axis-aligned box, world NED (lo.z() is the top).
struct Aabb {
  Vec3 lo;
  Vec3 hi;
};

/// The box grown by `margin` on every face (shrunk when negative).
Aabb inflated(const Aabb& box, double margin);

/// Whether p lies in the box's interior (not on a face).
bool strictly_inside(const Aabb& box, const Vec3& p);

/// Chebyshev distance from p to the box (0 inside): the largest inflation
/// of the box that leaves p outside.
double outside_distance(const Aabb& box, const Vec3& p);

/// Whether the segment p -> q meets the closed box (slab test).
bool segment_meets(const Aabb& box, const Vec3& p, const Vec3& q);

/// Boxes bucketed on a horizontal grid (compressed rows), so that a segment
/// or point meets only the boxes of the cells it passes. About one box per
/// cell, at most 256 cells a side.
class BoxGrid {
 public:
  explicit BoxGrid(const std::vector<Aabb>& boxes);

  /// Calls visit(box index) for every box whose cells the horizontal
  /// projection of p -> q passes (a box may come more than once, and a box
  /// that shares a cell without meeting the segment may come too: the
  /// caller tests the box itself). Every box whose footprint the
  /// projection meets comes at least once.
  template <class Visit>
  void along_segment(const Vec3& p, const Vec3& q, Visit&& visit) const {
    if (items_.empty()) return;
    const double x_min = std::min(p.x(), q.x()), x_max = std::max(p.x(), q.x());
    const double y_min = std::min(p.y(), q.y()), y_max = std::max(p.y(), q.y());
    if (x_max < x0_ || x_min > x0_ + nx_ * cell_ || y_max < y0_ || y_min > y0_ + ny_ * cell_)
      return;
    const double dx = q.x() - p.x();
    const int ix0 = clamp_x(x_min), ix1 = clamp_x(x_max);
    for (int ix = ix0; ix <= ix1; ++ix) {
      // The y extent of the segment within this column of cells.
      double ya = y_min, yb = y_max;
      if (std::abs(dx) > 1e-9) {
        const double xa = std::max(x_min, x0_ + ix * cell_);
        const double xb = std::min(x_max, x0_ + (ix + 1) * cell_);
        const double y_at_a = p.y() + (xa - p.x()) / dx * (q.y() - p.y());
        const double y_at_b = p.y() + (xb - p.x()) / dx * (q.y() - p.y());
        ya = std::min(y_at_a, y_at_b);
        yb = std::max(y_at_a, y_at_b);
      }
      if (yb < y0_ || ya > y0_ + ny_ * cell_) continue;
      const int iy0 = clamp_y(ya), iy1 = clamp_y(yb);
      for (int iy = iy0; iy <= iy1; ++iy) {
        const int c = ix * ny_ + iy;
        for (int k = cell_start_[c]; k < cell_start_[c + 1]; ++k) visit(items_[k]);
      }
    }
  }

  /// As along_segment() for the point p.
  template <class Visit>
  void at_point(const Vec3& p, Visit&& visit) const {
    along_segment(p, p, visit);
  }

 private:
  static constexpr double kMaxCells = 256.0;
  int clamp_x(double x) const {
    return std::clamp(static_cast<int>(std::floor((x - x0_) / cell_)), 0, nx_ - 1);
  }
  int clamp_y(double y) const {
    return std::clamp(static_cast<int>(std::floor((y - y0_) / cell_)), 0, ny_ - 1);
  }

  double x0_ = 0, y0_ = 0, cell_ = 1;
  int nx_ = 0, ny_ = 0;
  std::vector<int> cell_start_;
  std::vector<int> items_;
};

}  // namespace ofn::planning
