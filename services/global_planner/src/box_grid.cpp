#include "ofn/global_planner/box_grid.hpp"

#include <utility>

namespace ofn::planning {

Aabb inflated(const Aabb& box, double margin) {
  return {box.lo - Vec3::Constant(margin), box.hi + Vec3::Constant(margin)};
}

bool strictly_inside(const Aabb& box, const Vec3& p) {
  return (p.array() > box.lo.array()).all() && (p.array() < box.hi.array()).all();
}

double outside_distance(const Aabb& box, const Vec3& p) {
  const Vec3 gap = (box.lo - p).cwiseMax(p - box.hi);
  return std::max(0.0, gap.maxCoeff());
}

bool segment_meets(const Aabb& box, const Vec3& p, const Vec3& q) {
  double t_enter = 0.0;
  double t_exit = 1.0;
  for (int axis = 0; axis < 3; ++axis) {
    const double d = q[axis] - p[axis];
    if (std::abs(d) < 1e-12) {
      if (p[axis] < box.lo[axis] || p[axis] > box.hi[axis]) return false;
      continue;
    }
    double ta = (box.lo[axis] - p[axis]) / d;
    double tb = (box.hi[axis] - p[axis]) / d;
    if (ta > tb) std::swap(ta, tb);
    t_enter = std::max(t_enter, ta);
    t_exit = std::min(t_exit, tb);
    if (t_enter > t_exit) return false;
  }
  return true;
}

BoxGrid::BoxGrid(const std::vector<Aabb>& boxes) {
  if (boxes.empty()) return;
  constexpr double kInf = std::numeric_limits<double>::infinity();
  double x_lo = kInf, y_lo = kInf, x_hi = -kInf, y_hi = -kInf;
  for (const Aabb& b : boxes) {
    x_lo = std::min(x_lo, b.lo.x());
    y_lo = std::min(y_lo, b.lo.y());
    x_hi = std::max(x_hi, b.hi.x());
    y_hi = std::max(y_hi, b.hi.y());
  }
  // About one box per cell keeps both the cell lists and the cells a
  // segment crosses short.
  const double area = std::max(1.0, (x_hi - x_lo) * (y_hi - y_lo));
  cell_ = std::max(1.0, std::sqrt(area / static_cast<double>(boxes.size())));
  cell_ = std::max({cell_, (x_hi - x_lo) / kMaxCells, (y_hi - y_lo) / kMaxCells});
  x0_ = x_lo;
  y0_ = y_lo;
  nx_ = std::max(1, static_cast<int>(std::ceil((x_hi - x_lo) / cell_)));
  ny_ = std::max(1, static_cast<int>(std::ceil((y_hi - y_lo) / cell_)));
  std::vector<int> counts(static_cast<size_t>(nx_) * ny_ + 1, 0);
  auto for_cells = [&](const Aabb& b, auto&& visit) {
    const int ix0 = clamp_x(b.lo.x()), ix1 = clamp_x(b.hi.x());
    const int iy0 = clamp_y(b.lo.y()), iy1 = clamp_y(b.hi.y());
    for (int ix = ix0; ix <= ix1; ++ix)
      for (int iy = iy0; iy <= iy1; ++iy) visit(ix * ny_ + iy);
  };
  for (const Aabb& b : boxes) for_cells(b, [&](int c) { ++counts[c + 1]; });
  for (size_t c = 1; c < counts.size(); ++c) counts[c] += counts[c - 1];
  cell_start_ = counts;
  items_.resize(static_cast<size_t>(counts.back()));
  for (size_t i = 0; i < boxes.size(); ++i)
    for_cells(boxes[i], [&](int c) { items_[counts[c]++] = static_cast<int>(i); });
}

}  // namespace ofn::planning
