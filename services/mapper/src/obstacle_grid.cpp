#include "ofn/mapper/obstacle_grid.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <stdexcept>
#include <string>

namespace ofn::mapping {

namespace {

void require(bool ok, const char* field, const char* what) {
  if (!ok) throw std::invalid_argument(std::string("obstacle grid: ") + field + " " + what);
}

}  // namespace

ObstacleGrid::ObstacleGrid(const ObstacleGridConfig& config) : config_(config) {
  require(std::isfinite(config.resolution) && config.resolution > 0, "resolution", "must be > 0");
  require(std::isfinite(config.half_extent) && config.half_extent > 0, "half_extent",
          "must be > 0");
  require(std::isfinite(config.safety_margin) && config.safety_margin >= 0, "safety_margin",
          "must be >= 0");
  require(config.smoothing_radius >= 0, "smoothing_radius", "must be >= 0");
  require(std::isfinite(config.ground_altitude), "ground_altitude", "must be finite");
  require(std::isfinite(config.ground_clearance), "ground_clearance", "must be finite");
  require(std::isfinite(config.ceiling) && config.ceiling > 0, "ceiling", "must be > 0");
  // A tiny tolerance keeps e.g. 140.0000001 cells from becoming 141.
  const double cells = std::ceil(2.0 * config.half_extent / config.resolution - 1e-9);
  require(cells * cells <= 4.0e6, "half_extent", "gives more than 4e6 cells at this resolution");
  const int side = std::max(1, static_cast<int>(cells));

  raw_.resolution = config.resolution;
  raw_.rows = side;
  raw_.cols = side;
  raw_.origin_north = -0.5 * side * config.resolution;
  raw_.origin_east = raw_.origin_north;
  raw_.top.assign(static_cast<size_t>(side) * side, 0.0f);
  initial_origin_north_ = raw_.origin_north;
  initial_origin_east_ = raw_.origin_east;
  filtered_ = raw_;
  inflated_ = raw_.top;
  scratch_ = raw_.top;

  const double margin_cells = config.safety_margin / config.resolution;
  const int reach = static_cast<int>(std::floor(margin_cells + 1e-9));
  const double reach_sq = margin_cells * margin_cells + 1e-9;
  for (int dr = -reach; dr <= reach; ++dr)
    for (int dc = -reach; dc <= reach; ++dc)
      if (dr * dr + dc * dc <= reach_sq) margin_disc_.push_back({dr, dc});
}

void ObstacleGrid::recentre(double vehicle_north, double vehicle_east) {
  if (!std::isfinite(vehicle_north) || !std::isfinite(vehicle_east)) return;
  const double res = raw_.resolution;
  const double off_rows = (vehicle_north - (raw_.origin_north + 0.5 * raw_.rows * res)) / res;
  const double off_cols = (vehicle_east - (raw_.origin_east + 0.5 * raw_.cols * res)) / res;
  // Hysteresis of one cell: the grid does not chatter when the vehicle
  // hovers near a cell boundary.
  const auto shift_of = [](double offset) -> int64_t {
    return std::abs(offset) >= 1.0 ? static_cast<int64_t>(std::llround(offset)) : 0;
  };
  const int64_t shift_rows = shift_of(off_rows);
  const int64_t shift_cols = shift_of(off_cols);
  if (shift_rows == 0 && shift_cols == 0) return;

  shifted_rows_ += shift_rows;
  shifted_cols_ += shift_cols;
  raw_.origin_north = initial_origin_north_ + static_cast<double>(shifted_rows_) * res;
  raw_.origin_east = initial_origin_east_ + static_cast<double>(shifted_cols_) * res;
  filtered_.origin_north = raw_.origin_north;
  filtered_.origin_east = raw_.origin_east;
  dirty_ = true;

  const int rows = raw_.rows, cols = raw_.cols;
  const bool empty = row_lo_ > row_hi_;
  if (empty || std::abs(shift_rows) >= rows || std::abs(shift_cols) >= cols) {
    std::fill(raw_.top.begin(), raw_.top.end(), 0.0f);
    row_lo_ = col_lo_ = 0;
    row_hi_ = col_hi_ = -1;
    return;
  }
  // New cell (r, c) is old cell (r + shift_rows, c + shift_cols).
  const int sr = static_cast<int>(shift_rows), sc = static_cast<int>(shift_cols);
  std::fill(scratch_.begin(), scratch_.end(), 0.0f);
  const int new_row_lo = std::max(0, row_lo_ - sr), new_row_hi = std::min(rows - 1, row_hi_ - sr);
  const int new_col_lo = std::max(0, col_lo_ - sc), new_col_hi = std::min(cols - 1, col_hi_ - sc);
  if (new_row_lo <= new_row_hi && new_col_lo <= new_col_hi) {
    const size_t width = static_cast<size_t>(new_col_hi - new_col_lo + 1);
    for (int r = new_row_lo; r <= new_row_hi; ++r) {
      const float* from = &raw_.top[static_cast<size_t>(r + sr) * cols + (new_col_lo + sc)];
      std::copy(from, from + width, &scratch_[static_cast<size_t>(r) * cols + new_col_lo]);
    }
    row_lo_ = new_row_lo;
    row_hi_ = new_row_hi;
    col_lo_ = new_col_lo;
    col_hi_ = new_col_hi;
  } else {
    row_lo_ = col_lo_ = 0;
    row_hi_ = col_hi_ = -1;
  }
  raw_.top.swap(scratch_);
}

void ObstacleGrid::extend_bounds(int row, int col) {
  if (row_lo_ > row_hi_) {
    row_lo_ = row_hi_ = row;
    col_lo_ = col_hi_ = col;
    return;
  }
  row_lo_ = std::min(row_lo_, row);
  row_hi_ = std::max(row_hi_, row);
  col_lo_ = std::min(col_lo_, col);
  col_hi_ = std::max(col_hi_, col);
}

int64_t ObstacleGrid::insert_hits(const std::vector<Vec3>& points) {
  const double ceiling = config_.ceiling;
  int64_t landed = 0;
  for (const Vec3& p : points) {
    if (!std::isfinite(p.x()) || !std::isfinite(p.y()) || !std::isfinite(p.z())) continue;
    const double altitude = -p.z() - config_.ground_altitude;
    if (!(altitude >= config_.ground_clearance)) continue;
    const int row = raw_.row_of(p.x()), col = raw_.col_of(p.y());
    if (!raw_.inside(row, col)) continue;
    ++landed;
    const float top = static_cast<float>(std::min(altitude, ceiling));
    float& cell = raw_.at(row, col);
    if (top > cell) {
      cell = top;
      dirty_ = true;
      extend_bounds(row, col);
    }
  }
  return landed;
}

void ObstacleGrid::lower_cell(int row, int col, float altitude) {
  if (!raw_.inside(row, col) || std::isnan(altitude)) return;
  float& cell = raw_.at(row, col);
  const float lowered = std::max(0.0f, altitude);
  if (lowered < cell) {
    cell = lowered;
    dirty_ = true;
  }
}

const Heightfield& ObstacleGrid::filtered() {
  if (dirty_) {
    recompute_filtered();
    dirty_ = false;
  }
  return filtered_;
}

void ObstacleGrid::recompute_filtered() {
  std::fill(filtered_.top.begin(), filtered_.top.end(), 0.0f);
  if (row_lo_ > row_hi_) return;
  const int rows = raw_.rows, cols = raw_.cols;
  const auto index = [cols](int r, int c) { return static_cast<size_t>(r) * cols + c; };

  // Inflation: every nonzero raw top is spread over the margin disc.
  std::fill(inflated_.begin(), inflated_.end(), 0.0f);
  int reach = 0;
  for (const CellOffset& o : margin_disc_) reach = std::max(reach, std::abs(o.rows));
  for (int r = row_lo_; r <= row_hi_; ++r) {
    for (int c = col_lo_; c <= col_hi_; ++c) {
      const float top = raw_.top[index(r, c)];
      if (top <= 0.0f) continue;
      for (const CellOffset& o : margin_disc_) {
        const int rr = r + o.rows, cc = c + o.cols;
        if (!raw_.inside(rr, cc)) continue;
        float& v = inflated_[index(rr, cc)];
        v = std::max(v, top);
      }
    }
  }
  const int inf_row_lo = std::max(0, row_lo_ - reach),
            inf_row_hi = std::min(rows - 1, row_hi_ + reach);
  const int inf_col_lo = std::max(0, col_lo_ - reach),
            inf_col_hi = std::min(cols - 1, col_hi_ + reach);

  const int radius = config_.smoothing_radius;
  if (radius == 0) {
    for (int r = inf_row_lo; r <= inf_row_hi; ++r)
      for (int c = inf_col_lo; c <= inf_col_hi; ++c)
        filtered_.top[index(r, c)] = inflated_[index(r, c)];
    return;
  }

  // Separable box mean; everything outside the inflated box is zero, so only
  // that box grown by the radius can change.
  const int out_row_lo = std::max(0, inf_row_lo - radius),
            out_row_hi = std::min(rows - 1, inf_row_hi + radius);
  const int out_col_lo = std::max(0, inf_col_lo - radius),
            out_col_hi = std::min(cols - 1, inf_col_hi + radius);
  std::fill(scratch_.begin(), scratch_.end(), 0.0f);
  for (int r = inf_row_lo; r <= inf_row_hi; ++r) {
    for (int c = out_col_lo; c <= out_col_hi; ++c) {
      const int lo = std::max(inf_col_lo, c - radius), hi = std::min(inf_col_hi, c + radius);
      float sum = 0.0f;
      for (int k = lo; k <= hi; ++k) sum += inflated_[index(r, k)];
      scratch_[index(r, c)] = sum;
    }
  }
  const float inv_window = 1.0f / static_cast<float>((2 * radius + 1) * (2 * radius + 1));
  for (int r = out_row_lo; r <= out_row_hi; ++r) {
    const int lo = std::max(inf_row_lo, r - radius), hi = std::min(inf_row_hi, r + radius);
    for (int c = out_col_lo; c <= out_col_hi; ++c) {
      float sum = 0.0f;
      for (int k = lo; k <= hi; ++k) sum += scratch_[index(k, c)];
      filtered_.top[index(r, c)] = std::max(inflated_[index(r, c)], sum * inv_window);
    }
  }
}

}  // namespace ofn::mapping
