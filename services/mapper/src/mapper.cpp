#include "ofn/mapper/mapper.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace ofn::mapping {
namespace {

/// Cells a beam must continue past a cell for it to have passed over it:
/// one that runs out of range, well past it (it may have ended just behind
/// a face plane); one that ends in a hit, past the next cell (range noise
/// of centimetres cannot put the hit of a beam that met a face a whole cell
/// behind it, while a beam over a low cell that meets a taller one close
/// behind still shows the low cell's top: a ragged canopy).
constexpr double kSeenOverContinuationFree = 3.0;
constexpr double kSeenOverContinuationHit = 1.0;
/// Cells whose tops differ by no more than this (m) belong to one surface.
constexpr float kSameSurface = 0.5f;
/// Scans between clean-ups of the hit record.
constexpr int64_t kHitSpreadCleanup = 64;

}  // namespace

Mapper::Mapper(const MapperConfig& config)
    : config_(config),
      grid_(config.grid),
      confirmed_(config.grid),
      seen_over_(config.grid),
      hit_spread_(config.grid.resolution),
      occupancy_(config.occupancy),
      extractor_(config.cuboids),
      database_(config.database) {}

void Mapper::set_vehicle_position(const Vec3& ned) {
  vehicle_ = ned;
  grid_.recentre(ned.x(), ned.y());
  seen_over_.recentre(ned.x(), ned.y());
}

void Mapper::add_scan(const ScanInput& scan) {
  ++counters_.scans;
  counters_.points += grid_.insert_hits(scan.points);
  if (config_.top_over_hits) {
    // The obstacle hits the grid takes (not the ground's).
    for (const auto& p : scan.points)
      if (-p.z() - config_.grid.ground_altitude >= config_.grid.ground_clearance)
        hit_spread_.add(p);
    if (counters_.scans % kHitSpreadCleanup == 0)
      hit_spread_.forget_beyond(
          vehicle_, std::sqrt(2.0) * config_.grid.half_extent + config_.grid.resolution);
  }
  if (config_.use_occupancy)
    occupancy_.insert_scan(scan.sensor_origin, scan.points, scan.free_ray_ends);
  seen_points_.clear();
  for (const auto& p : scan.points)
    trace_over_tops(scan.sensor_origin, p, kSeenOverContinuationHit, seen_points_);
  for (const auto& p : scan.free_ray_ends)
    trace_over_tops(scan.sensor_origin, p, kSeenOverContinuationFree, seen_points_);
  seen_over_.insert_hits(seen_points_);
}

void Mapper::trace_over_tops(const Vec3& origin, const Vec3& end, double min_continuation,
                             std::vector<Vec3>& seen_points) const {
  // 2-D walk (Amanatides-Woo) through the cells under the beam. Only cells
  // the beam leaves again count, and only where it stays above the cell's
  // top by at most the band: then the space just above that top was seen.
  const Heightfield& raw = grid_.raw();
  if (raw.empty()) return;
  const double ground = config_.grid.ground_altitude;
  const double res = raw.resolution;
  const double a0 = -origin.z() - ground, a1 = -end.z() - ground;
  const double gn = (origin.x() - raw.origin_north) / res,
               ge = (origin.y() - raw.origin_east) / res;
  const double dn = (end.x() - origin.x()) / res, de = (end.y() - origin.y()) / res;
  // Only the part of the beam over the grid is walked (t in [t_in, t_out]
  // of its length): a beam of any length, or from a sensor anywhere, walks
  // at most the grid's rows + cols cells.
  double t_in = 0.0, t_out = 1.0;
  const auto clip = [&t_in, &t_out](double g, double d, int cells) {
    if (d == 0) return g >= 0 && g < cells;
    const double ta = (0 - g) / d, tb = (cells - g) / d;
    t_in = std::max(t_in, std::min(ta, tb));
    t_out = std::min(t_out, std::max(ta, tb));
    return true;
  };
  if (!std::isfinite(gn + ge + dn + de) || !clip(gn, dn, raw.rows) || !clip(ge, de, raw.cols) ||
      !(t_in < t_out))
    return;
  const double sn = gn + t_in * dn, se = ge + t_in * de;
  int row = std::clamp(static_cast<int>(std::floor(sn)), 0, raw.rows - 1);
  int col = std::clamp(static_cast<int>(std::floor(se)), 0, raw.cols - 1);
  const int step_r = dn > 0 ? 1 : -1, step_c = de > 0 ? 1 : -1;
  const double inf = std::numeric_limits<double>::infinity();
  const double dt_r = dn != 0 ? std::abs(1.0 / dn) : inf;
  const double dt_c = de != 0 ? std::abs(1.0 / de) : inf;
  double t_r = dn > 0 ? (row + 1 - gn) * dt_r : dn < 0 ? (gn - row) * dt_r : inf;
  double t_c = de > 0 ? (col + 1 - ge) * dt_c : de < 0 ? (ge - col) * dt_c : inf;
  // The sensor's own cell is not one the beam left; a cell it entered from
  // outside the grid is.
  double t_enter = t_in;
  const double band = config_.top_seen_band;
  // The beam must go on well past the cell: one that runs out of range just
  // behind a wall's face plane (or skims the free front part of a face
  // cell) proves nothing, one that continues several cells at that height
  // without a return proves the wall is not there.
  const double length_cells = std::hypot(dn, de);
  while (t_enter < t_out) {
    const double t_exit = std::min(t_r, t_c);
    if ((1.0 - t_exit) * length_cells < min_continuation) break;
    if (t_enter > 0 && raw.inside(row, col)) {
      const float top = raw.at(row, col);
      if (top > 0.0f) {
        const double lowest = std::min(a0 + t_enter * (a1 - a0), a0 + t_exit * (a1 - a0));
        if (lowest > top && lowest <= top + band &&
            (!config_.top_over_hits ||
             hit_spread_.straddled(raw.cell_centre_north(row), raw.cell_centre_east(col), origin,
                                   end, config_.top_over_hits_margin)))
          seen_points.emplace_back(raw.cell_centre_north(row), raw.cell_centre_east(col),
                                   -(ground + top));
      }
    }
    t_enter = t_exit;
    if (t_r < t_c) {
      row += step_r;
      t_r += dt_r;
    } else {
      col += step_c;
      t_c += dt_c;
    }
  }
}

const Heightfield& Mapper::grid() {
  // Seen from below, a face shows as high as the scanner looked, and a
  // vehicle climbing beside it towards that line would meet the rest of it
  // (a 600 ft wall mapped at the 42.5 deg edge of the scan). So a top is
  // known only where a beam went over it, or on the same surface: cells
  // joined to such a cell through neighbours whose tops lie within
  // kSameSurface of the top the beam went over (a wall's end cells, hit
  // once at the edge of the sweep and never looked over again). Every
  // other top may reach the ceiling, and the optimiser, the commit gate and
  // the shadows treat it so.
  const Heightfield& raw = grid_.raw();
  const Heightfield& seen = seen_over_.raw();
  const size_t cells = raw.top.size();
  top_known_.assign(cells, 0);
  frontier_.clear();
  for (int r = 0; r < raw.rows; ++r)
    for (int c = 0; c < raw.cols; ++c) {
      const float top = raw.at(r, c);
      if (top > 0.0f && seen.at(r, c) >= top - 1e-3f) {
        top_known_[static_cast<size_t>(r) * raw.cols + c] = 1;
        frontier_.push_back({r, c, top});
      }
    }
  while (!frontier_.empty()) {
    const KnownTop cell = frontier_.back();
    frontier_.pop_back();
    for (int dr = -1; dr <= 1; ++dr)
      for (int dc = -1; dc <= 1; ++dc) {
        const int r = cell.row + dr, c = cell.col + dc;
        if (!raw.inside(r, c)) continue;
        const size_t i = static_cast<size_t>(r) * raw.cols + c;
        const float top = raw.top[i];
        if (top_known_[i] || top <= 0.0f || std::abs(top - cell.seen_top) > kSameSurface) continue;
        top_known_[i] = 1;
        frontier_.push_back({r, c, cell.seen_top});
      }
  }
  // The unknown tops go up to the ceiling over the cells their hits
  // inflate (the safety margin); the smoothing ramp beside them stays what
  // the hits make it, so an unseen top does not widen its obstacle.
  published_ = grid_.filtered();
  const auto ceiling = static_cast<float>(config_.grid.ceiling);
  const double margin = config_.grid.safety_margin;
  const int reach = static_cast<int>(std::floor(margin / raw.resolution));
  for (int r = 0; r < raw.rows; ++r)
    for (int c = 0; c < raw.cols; ++c) {
      if (raw.at(r, c) <= 0.0f || top_known_[static_cast<size_t>(r) * raw.cols + c]) continue;
      for (int dr = -reach; dr <= reach; ++dr)
        for (int dc = -reach; dc <= reach; ++dc)
          if (published_.inside(r + dr, c + dc) &&
              std::hypot(dr, dc) * raw.resolution <= margin + 1e-9)
            published_.at(r + dr, c + dc) = ceiling;
    }
  return published_;
}

bool Mapper::rectangle_top_seen(double min_n, double min_e, double max_n, double max_e,
                                double top) const {
  // The cells that hold the rectangle's top decide: seen if a beam passed
  // over any of them at their present height.
  const Heightfield& raw = grid_.raw();
  const Heightfield& seen = seen_over_.raw();
  const double eps = 1e-6 * raw.resolution;
  const int r0 = std::max(0, raw.row_of(min_n + eps)),
            r1 = std::min(raw.rows - 1, raw.row_of(max_n - eps));
  const int c0 = std::max(0, raw.col_of(min_e + eps)),
            c1 = std::min(raw.cols - 1, raw.col_of(max_e - eps));
  const double tolerance = config_.occupancy.resolution + raw.resolution;
  for (int r = r0; r <= r1; ++r)
    for (int c = c0; c <= c1; ++c) {
      const float cell_top = raw.at(r, c);
      if (cell_top > 0.0f && cell_top >= top - tolerance && seen.at(r, c) >= cell_top - 1e-3f)
        return true;
    }
  return false;
}

template <class Visit>
void Mapper::for_each_column_top(double min_probability, Visit visit) const {
  // Altitudes of the occupancy queries are above the ground, like the grid's.
  const Heightfield& raw = grid_.raw();
  const double voxel = config_.occupancy.resolution;
  const double half = 0.5 * raw.resolution;
  for (int r = 0; r < raw.rows; ++r)
    for (int c = 0; c < raw.cols; ++c) {
      const float top = raw.at(r, c);
      if (top <= 0.0f) continue;
      visit(r, c, top,
            occupancy_.column_top(raw.cell_centre_north(r), raw.cell_centre_east(c), half,
                                  config_.grid.ground_clearance, top + voxel, min_probability));
    }
}

void Mapper::reconcile_with_occupancy() {
  // A grid cell keeps its highest hit for ever in the paper's design. Here
  // the occupancy map has the last word: where beams have since passed
  // through the space a hit claimed, the cell comes down to what is still
  // occupied (nothing, for a false return or a removed obstacle).
  const double voxel = config_.occupancy.resolution;
  for_each_column_top(0.0, [&](int r, int c, float top, double occupied_top) {
    if (occupied_top < 0) {
      grid_.lower_cell(r, c, 0.0f);
      ++counters_.cells_lowered;
    } else if (occupied_top < top - voxel) {
      grid_.lower_cell(r, c, static_cast<float>(occupied_top));
      ++counters_.cells_lowered;
    }
  });
}

Heightfield Mapper::confirmed_grid() {
  // The planner's cuboids come only from cells whose column the occupancy
  // map holds with confidence: one stray return shows in the grid at once
  // (conservative for the optimiser) but must be seen again before it can
  // become an obstacle in the database.
  confirmed_ = grid_;
  for_each_column_top(config_.confirm_probability, [&](int r, int c, float top,
                                                       double confirmed_top) {
    confirmed_.lower_cell(
        r, c, confirmed_top < 0 ? 0.0f : static_cast<float>(std::min<double>(top, confirmed_top)));
  });
  return confirmed_.filtered();
}

void Mapper::update_cuboids(Utime now) {
  ++counters_.cycles;
  Heightfield source;
  if (config_.use_occupancy) {
    reconcile_with_occupancy();
    occupancy_.forget_far(vehicle_.x(), vehicle_.y());
    source = confirmed_grid();
  } else {
    source = grid_.filtered();
  }
  const double ground = config_.grid.ground_altitude;
  const CuboidExtractor::TopSeen top_seen = [this, ground](double min_n, double min_e, double max_n,
                                                           double max_e, double top_altitude) {
    return rectangle_top_seen(min_n, min_e, max_n, max_e, top_altitude - ground);
  };
  extracted_ = extractor_.extract(source, top_seen);

  // Only obstacles whose footprint lies wholly on the grid could have been
  // found again; the rest were left behind and are kept as they are.
  const double n0 = source.origin_north, e0 = source.origin_east;
  const double n1 = n0 + source.rows * source.resolution;
  const double e1 = e0 + source.cols * source.resolution;
  // A blob cut by the grid's edge is only the part still on the grid: it
  // extends what the database knows of that obstacle instead of replacing it.
  const double edge = source.resolution * 1.5;
  for (auto& c : extracted_) {
    const bool cut = c.min.x() < n0 + edge || c.max.x() > n1 - edge || c.min.y() < e0 + edge ||
                     c.max.y() > e1 - edge;
    if (!cut) continue;
    for (const auto& entry : database_.entries()) {
      if (footprint_overlap(c, entry.cuboid) < config_.database.match_overlap) continue;
      // The higher top wins, with what is known about it.
      if (entry.cuboid.min.z() < c.min.z()) c.top_observed = entry.cuboid.top_observed;
      c.min = c.min.cwiseMin(entry.cuboid.min);
      c.max = c.max.cwiseMax(entry.cuboid.max);
    }
  }
  // Extended pieces of one obstacle may now coincide: keep one of each.
  auto contains = [](const Cuboid& outer, const Cuboid& inner) {
    return (outer.min.array() <= inner.min.array()).all() &&
           (outer.max.array() >= inner.max.array()).all();
  };
  for (size_t i = 0; i < extracted_.size(); ++i)
    for (size_t j = 0; j < extracted_.size(); ++j)
      if (i != j && contains(extracted_[j], extracted_[i]) &&
          (!contains(extracted_[i], extracted_[j]) || j < i)) {
        extracted_.erase(extracted_.begin() + static_cast<std::ptrdiff_t>(i));
        --i;
        break;
      }
  database_.update(extracted_, now, [=](const Cuboid& c) {
    return c.min.x() >= n0 && c.max.x() <= n1 && c.min.y() >= e0 && c.max.y() <= e1;
  });
}

}  // namespace ofn::mapping
