#include "ofn/rh_optimizer/occlusion.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <stdexcept>
#include <utility>
#include <vector>

#include "ofn/map/cell_key.hpp"

namespace ofn::rh {
int64_t VisibilityRecord::key(double north, double east) const {
  return mapping::cell_key(north, east, resolution_);
}

void VisibilityRecord::add_beam(const Vec3& origin, const Vec3& end, bool hit,
                                double vehicle_altitude) {
  Vec3 d = end - origin;
  double horizontal = std::hypot(d.x(), d.y());
  if (!(horizontal > 0) || !std::isfinite(horizontal) || !std::isfinite(d.z())) return;
  if (horizontal > max_reach_) {
    d *= max_reach_ / horizontal;
    horizontal = max_reach_;
    hit = false;
  }
  // Stop a cell short of a hit: that cell holds the obstacle.
  const double reach = (hit ? horizontal - resolution_ : horizontal) / horizontal;
  if (!(reach > 0)) return;
  // The beam's altitude is linear along it: only the stretch within the
  // band around the vehicle's altitude counts.
  const double a0 = -origin.z() - vehicle_altitude, slope = -d.z();
  double f_lo = 0.0, f_hi = reach;
  if (std::abs(slope) < 1e-9) {
    if (std::abs(a0) > band_) return;
  } else {
    const double fa = (-band_ - a0) / slope, fb = (band_ - a0) / slope;
    f_lo = std::max(f_lo, std::min(fa, fb));
    f_hi = std::min(f_hi, std::max(fa, fb));
    if (f_hi < f_lo) return;
  }
  const double df = 0.5 * resolution_ / horizontal;
  for (double f = f_lo; f <= f_hi; f += df) {
    const Vec3 p = origin + f * d;
    cells_.insert(key(p.x(), p.y()));
  }
}

void VisibilityRecord::forget_beyond(const Vec3& centre, double radius) {
  const double r2 = radius * radius;
  for (auto it = cells_.begin(); it != cells_.end();) {
    const auto [north, east] = mapping::cell_key_centre(*it, resolution_);
    const double dn = north - centre.x(), de = east - centre.y();
    it = dn * dn + de * de > r2 ? cells_.erase(it) : std::next(it);
  }
}

int64_t ShadowMemory::key(double north, double east) const {
  return mapping::cell_key(north, east, resolution_);
}

void ShadowMemory::remember(double north, double east, float top, double occluder_north,
                            double occluder_east) {
  Shadow& shadow = tops_[key(north, east)];
  if (top > shadow.top) shadow = {top, occluder_north, occluder_east};
}

int ShadowMemory::apply(mapping::Heightfield& grid, const VisibilityRecord& visibility) {
  int raised = 0;
  for (auto it = tops_.begin(); it != tops_.end();) {
    const auto [north, east] = mapping::cell_key_centre(it->first, resolution_);
    const Shadow& shadow = it->second;
    const int orow = grid.row_of(shadow.occluder_north), ocol = grid.col_of(shadow.occluder_east);
    const bool occluder_stands = grid.inside(orow, ocol) && grid.at(orow, ocol) >= shadow.top;
    if (visibility.seen(north, east) || !occluder_stands) {
      it = tops_.erase(it);
      continue;
    }
    const int r = grid.row_of(north), c = grid.col_of(east);
    if (grid.inside(r, c) && grid.at(r, c) < shadow.top) {
      grid.at(r, c) = shadow.top;
      ++raised;
    }
    ++it;
  }
  return raised;
}

void ShadowMemory::forget_beyond(const Vec3& centre, double radius) {
  const double r2 = radius * radius;
  for (auto it = tops_.begin(); it != tops_.end();) {
    const auto [north, east] = mapping::cell_key_centre(it->first, resolution_);
    const double dn = north - centre.x(), de = east - centre.y();
    it = dn * dn + de * de > r2 ? tops_.erase(it) : std::next(it);
  }
}

int cast_occlusion_shadows(mapping::Heightfield& grid, const VisibilityRecord& visibility,
                           const Vec3& vehicle, double altitude, double depth, double near,
                           ShadowMemory* memory) {
  if (grid.empty() || !(depth > 0)) return 0;
  struct Occluder {
    int row, col;
    float top;
  };
  // Collected first: shadows cast none of their own.
  std::vector<Occluder> occluders;
  for (int r = 0; r < grid.rows; ++r)
    for (int c = 0; c < grid.cols; ++c)
      if (grid.at(r, c) > altitude) occluders.push_back({r, c, grid.at(r, c)});
  const double step = 0.5 * grid.resolution;
  const int steps = static_cast<int>(std::ceil(depth / step));
  int raised = 0;
  for (const auto& o : occluders) {
    const double north = grid.cell_centre_north(o.row);
    const double east = grid.cell_centre_east(o.col);
    const double dn = north - vehicle.x(), de = east - vehicle.y();
    const double range = std::hypot(dn, de);
    if (range < near) continue;
    const double un = dn / range, ue = de / range;
    for (int k = 1; k <= steps; ++k) {
      const double n = north + un * step * k, e = east + ue * step * k;
      if (visibility.seen(n, e)) break;
      const int r = grid.row_of(n), c = grid.col_of(e);
      if (!grid.inside(r, c)) break;
      if (memory) memory->remember(n, e, o.top, north, east);
      float& top = grid.at(r, c);
      if (top < o.top) {
        top = o.top;
        ++raised;
      }
    }
  }
  return raised;
}

int extend_into_unseen(const mapping::Heightfield& mapped, mapping::Heightfield& grid,
                       const VisibilityRecord& visibility, const Vec3& vehicle, double reach,
                       float min_top, float top) {
  if (mapped.empty() || !(reach > 0)) return 0;
  if (mapped.rows != grid.rows || mapped.cols != grid.cols)
    throw std::invalid_argument("extend_into_unseen: the grids differ in size");
  const int cells = static_cast<int>(std::floor(reach / mapped.resolution));
  const double reach_cells = reach / mapped.resolution + 1e-9;
  auto range = [&](int r, int c) {
    return std::hypot(mapped.cell_centre_north(r) - vehicle.x(),
                      mapped.cell_centre_east(c) - vehicle.y());
  };
  // Whether a beam crossed each cell, looked up once per cell: -1 not yet.
  std::vector<int8_t> seen(mapped.top.size(), -1);
  int raised = 0;
  for (int row = 0; row < mapped.rows; ++row)
    for (int col = 0; col < mapped.cols; ++col) {
      if (!(mapped.at(row, col) > min_top)) continue;
      const double obstacle_range = range(row, col) - 0.5 * mapped.resolution;
      for (int dr = -cells; dr <= cells; ++dr)
        for (int dc = -cells; dc <= cells; ++dc) {
          const int r = row + dr, c = col + dc;
          if (std::hypot(dr, dc) > reach_cells || !mapped.inside(r, c)) continue;
          if (grid.at(r, c) > min_top || range(r, c) < obstacle_range) continue;
          int8_t& looked = seen[static_cast<size_t>(r) * mapped.cols + c];
          if (looked < 0)
            looked = visibility.seen(mapped.cell_centre_north(r), mapped.cell_centre_east(c));
          if (looked) continue;
          grid.at(r, c) = top;
          ++raised;
        }
    }
  return raised;
}

int raise_unseen_near(mapping::Heightfield& grid, const VisibilityRecord& visibility,
                      const Vec3& vehicle, double exempt, double reach, float top) {
  if (grid.empty() || !(reach > exempt) || !vehicle.allFinite()) return 0;
  const int r_lo = std::max(0, grid.row_of(vehicle.x() - reach));
  const int r_hi = std::min(grid.rows - 1, grid.row_of(vehicle.x() + reach));
  const int c_lo = std::max(0, grid.col_of(vehicle.y() - reach));
  const int c_hi = std::min(grid.cols - 1, grid.col_of(vehicle.y() + reach));
  int raised = 0;
  for (int r = r_lo; r <= r_hi; ++r)
    for (int c = c_lo; c <= c_hi; ++c) {
      const double north = grid.cell_centre_north(r), east = grid.cell_centre_east(c);
      const double range = std::hypot(north - vehicle.x(), east - vehicle.y());
      if (range < exempt || range > reach || !(grid.at(r, c) < top)) continue;
      if (visibility.seen(north, east)) continue;
      grid.at(r, c) = top;
      ++raised;
    }
  return raised;
}

}  // namespace ofn::rh
