#include "ofn/map/distance_field.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <stdexcept>
#include <string>

namespace ofn::mapping {

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

// A cell's top as the field keeps it: free cells are -inf (no exterior
// site, and air at every altitude).
float stored_top(float top, double occupied_above) {
  return top > occupied_above ? top : -kInf;
}

void require(bool ok, const char* field, const char* what) {
  if (!ok) throw std::invalid_argument(std::string("distance field: ") + field + " " + what);
}

// Felzenszwalb-Huttenlocher lower envelope, unit spacing:
//   out[q * out_stride] = min_p (q - p)^2 + cost[p].
// Costs and results above `cap` become kInf: everything beyond it is clamped
// to max_distance anyway, and dropping those sites keeps the far field cheap.
void transform_1d(const float* cost, int n, float cap, float* out, int out_stride, int* site,
                  float* site_cost, float* from) {
  int last = -1;
  for (int q = 0; q < n; ++q) {
    const float c = cost[q];
    if (!(c <= cap)) continue;
    const float lifted = c + static_cast<float>(q) * static_cast<float>(q);
    if (last < 0) {
      last = 0;
      site[0] = q;
      site_cost[0] = c;
      from[0] = -kInf;
      continue;
    }
    for (;;) {
      const int p = site[last];
      const float s = (lifted - (site_cost[last] + static_cast<float>(p) * static_cast<float>(p))) /
                      (2.0f * static_cast<float>(q - p));
      // from[0] is -inf, so the first parabola is never popped.
      if (s <= from[last]) {
        --last;
        continue;
      }
      ++last;
      site[last] = q;
      site_cost[last] = c;
      from[last] = s;
      break;
    }
  }
  if (last < 0) {
    for (int q = 0; q < n; ++q) out[static_cast<std::ptrdiff_t>(q) * out_stride] = kInf;
    return;
  }
  int k = 0;
  for (int q = 0; q < n; ++q) {
    while (k < last && from[k + 1] < static_cast<float>(q)) ++k;
    const float d = static_cast<float>(q - site[k]);
    const float value = d * d + site_cost[k];
    out[static_cast<std::ptrdiff_t>(q) * out_stride] = value <= cap ? value : kInf;
  }
}

// Where a coordinate (in samples) falls between the samples of one axis.
struct AxisCell {
  int index = 0;        // lower sample
  int step = 0;         // 1, or 0 when the axis has a single sample
  double t = 0;         // fraction towards index + step
  bool varies = false;  // false where clamped: that gradient component is 0
};

inline AxisCell locate(double u, int samples) {
  AxisCell cell;
  cell.varies = true;
  const double last = samples - 1;
  if (!(u >= 0)) {  // also catches NaN
    u = 0;
    cell.varies = false;
  } else if (u > last) {
    u = last;
    cell.varies = false;
  }
  if (samples < 2) {
    cell.varies = false;
    return cell;
  }
  cell.index = std::min(static_cast<int>(u), samples - 2);
  cell.step = 1;
  cell.t = u - cell.index;
  return cell;
}

}  // namespace

void DistanceField::build(const Heightfield& field, double alt_lo, double alt_hi,
                          double occupied_above) {
  require(std::isfinite(config_.vertical_resolution) && config_.vertical_resolution > 0,
          "vertical_resolution", "must be > 0");
  require(std::isfinite(config_.max_distance) && config_.max_distance > 0, "max_distance",
          "must be > 0");
  require(std::isfinite(alt_lo) && std::isfinite(alt_hi) && alt_hi >= alt_lo, "alt_hi",
          "must be finite and >= alt_lo");
  require(std::isfinite(occupied_above), "occupied_above", "must be finite");
  require(field.rows >= 0 && field.cols >= 0, "heightfield size", "must be >= 0");
  const size_t cells = static_cast<size_t>(field.rows) * static_cast<size_t>(field.cols);
  require(field.top.size() == cells, "heightfield top", "must hold rows * cols values");
  require(field.empty() || (std::isfinite(field.resolution) && field.resolution > 0),
          "heightfield resolution", "must be > 0");
  // A tiny tolerance keeps e.g. 59.0000001 slices from becoming 61.
  const double span = std::ceil((alt_hi - alt_lo) / config_.vertical_resolution - 1e-9);
  require(span * static_cast<double>(cells) <= 1.0e8, "alt_hi",
          "gives more than 1e8 samples at this resolution");

  const int slices = field.empty() ? 0 : std::max(0, static_cast<int>(span)) + 1;
  // The same input as the last build (a hover re-maps the same cells): the
  // slices already transformed stay, bit for bit what a rebuild would give.
  if (same_input(field, alt_lo, slices, occupied_above)) return;

  geometry_.origin_north = field.origin_north;
  geometry_.origin_east = field.origin_east;
  geometry_.resolution = field.resolution;
  geometry_.rows = field.rows;
  geometry_.cols = field.cols;
  geometry_.top.clear();
  alt_lo_ = alt_lo;
  occupied_above_ = occupied_above;
  reaching_exterior_valid_ = false;
  slices_built_ = 0;
  slices_ = slices;
  if (field.empty()) {
    distance_.clear();
    slice_built_.clear();
    tops_.clear();
    return;
  }

  const int longest = std::max(field.rows, field.cols);
  tops_.resize(cells);
  sites_.resize(cells);
  transposed_.resize(cells);
  exterior_.resize(cells);
  reaching_exterior_.resize(cells);
  squared_.resize(cells);
  tops_transposed_.resize(cells);
  line_.resize(static_cast<size_t>(longest));
  envelope_site_.resize(static_cast<size_t>(longest));
  envelope_cost_.resize(static_cast<size_t>(longest));
  envelope_from_.resize(static_cast<size_t>(longest));
  distance_.resize(cells * static_cast<size_t>(slices_));
  slice_built_.assign(static_cast<size_t>(slices_), 0);

  min_occupied_top_ = kInf;
  for (size_t c = 0; c < cells; ++c) {
    tops_[c] = stored_top(field.top[c], occupied_above);
    if (tops_[c] > -kInf) min_occupied_top_ = std::min(min_occupied_top_, tops_[c]);
  }
  for (int r = 0; r < field.rows; ++r)
    for (int c = 0; c < field.cols; ++c)
      tops_transposed_[static_cast<size_t>(c) * field.rows + r] =
          tops_[static_cast<size_t>(r) * field.cols + c];
}

bool DistanceField::same_input(const Heightfield& field, double alt_lo, int slices,
                               double occupied_above) const {
  // Compared as the build would store them: the geometry bit for bit, each
  // cell by whether it is an obstacle and its top.
  if (slices_ == 0 || slices != slices_ || alt_lo != alt_lo_ || occupied_above != occupied_above_ ||
      field.origin_north != geometry_.origin_north || field.origin_east != geometry_.origin_east ||
      field.resolution != geometry_.resolution || field.rows != geometry_.rows ||
      field.cols != geometry_.cols || field.top.size() != tops_.size())
    return false;
  for (size_t c = 0; c < tops_.size(); ++c)
    if (stored_top(field.top[c], occupied_above) != tops_[c]) return false;
  return true;
}

void DistanceField::build_all_slices() const {
  for (int k = 0; k < slices_; ++k) ensure_slice(k);
}

void DistanceField::ensure_slice(int k) const {
  if (slice_built_[static_cast<size_t>(k)]) return;
  const size_t cells = static_cast<size_t>(geometry_.rows) * static_cast<size_t>(geometry_.cols);
  build_slice(alt_lo_ + k * config_.vertical_resolution, distance_.data() + cells * k);
  slice_built_[static_cast<size_t>(k)] = 1;
  ++slices_built_;
}

void DistanceField::build_slice(double altitude, float* slice_out) const {
  const int rows = geometry_.rows, cols = geometry_.cols;
  const size_t cells = static_cast<size_t>(rows) * cols;
  const float res = static_cast<float>(geometry_.resolution);
  const float inv_res = 1.0f / res;
  const float max_distance = static_cast<float>(config_.max_distance);
  const float reach = max_distance * inv_res;
  const float cap = reach * reach * (1.0f + 1e-6f);
  const float h = static_cast<float>(altitude);
  int* site = envelope_site_.data();
  float* site_cost = envelope_cost_.data();
  float* from = envelope_from_.data();

  const auto to_distance = [&](float squared) {
    return std::min(res * std::sqrt(squared), max_distance);  // kInf -> max_distance
  };

  // Exterior: the cost of column c is its squared height below this slice.
  // While every column reaches the slice the costs are all 0 / inf, so the
  // lower slices share one transform.
  const bool every_column_reaches = h <= min_occupied_top_;
  const float* exterior = reaching_exterior_.data();
  if (!(every_column_reaches && reaching_exterior_valid_)) {
    for (size_t c = 0; c < cells; ++c) {
      const float below = (h - tops_[c]) * inv_res;
      sites_[c] = below > 0 ? below * below : 0.0f;
    }
    // Along rows into the transposed scratch, then along its rows (the
    // columns), so both passes read contiguous memory.
    float* transposed = transposed_.data();
    for (int r = 0; r < rows; ++r)
      transform_1d(sites_.data() + static_cast<size_t>(r) * cols, cols, cap, transposed + r, rows,
                   site, site_cost, from);
    for (int c = 0; c < cols; ++c)
      transform_1d(transposed + static_cast<size_t>(c) * rows, rows, cap, squared_.data() + c, cols,
                   site, site_cost, from);
    float* out = every_column_reaches ? reaching_exterior_.data() : exterior_.data();
    for (size_t c = 0; c < cells; ++c) out[c] = to_distance(squared_[c]);
    if (every_column_reaches) reaching_exterior_valid_ = true;
    exterior = out;
  }
  std::copy(exterior, exterior + cells, slice_out);

  // Interior: cells whose column rises above the slice. Their depth is the
  // same transform with air (cost 0) as the sites and each column's height
  // above the slice as its cost (the way out through its top). Along a line
  // nothing beyond the nearest air cell on either side can be closer, so
  // each run of inside cells is transformed between its two bounding air
  // cells only, and air cells keep 0: the cost is in the inside cells.
  const auto for_each_inside_run = [&](const float* tops, int n, auto&& transform_run) {
    for (int start = 0; start < n;) {
      if (!(tops[start] > h)) {
        ++start;
        continue;
      }
      int end = start + 1;
      while (end < n && tops[end] > h) ++end;
      const int lo = std::max(0, start - 1), hi = std::min(n - 1, end);
      transform_run(lo, hi - lo + 1);
      start = end;
    }
  };
  float* transposed = transposed_.data();
  std::fill(transposed, transposed + cells, 0.0f);
  for (int r = 0; r < rows; ++r) {
    const float* top = tops_.data() + static_cast<size_t>(r) * cols;
    float* cost = sites_.data() + static_cast<size_t>(r) * cols;
    for_each_inside_run(top, cols, [&](int lo, int n) {
      for (int c = lo; c < lo + n; ++c) {
        const float above = (top[c] - h) * inv_res;
        cost[c] = above > 0 ? above * above : 0.0f;
      }
      transform_1d(cost + lo, n, cap, transposed + static_cast<size_t>(lo) * rows + r, rows, site,
                   site_cost, from);
    });
  }
  float* line = line_.data();
  for (int c = 0; c < cols; ++c) {
    const float* top = tops_transposed_.data() + static_cast<size_t>(c) * rows;
    const float* cost = transposed + static_cast<size_t>(c) * rows;
    for_each_inside_run(top, rows, [&](int lo, int n) {
      transform_1d(cost + lo, n, cap, line, 1, site, site_cost, from);
      for (int r = lo; r < lo + n; ++r)
        if (top[r] > h) slice_out[static_cast<size_t>(r) * cols + c] = -to_distance(line[r - lo]);
    });
  }
}

template <bool kWithGradient>
double DistanceField::sample(const Vec3& ned, Vec3* gradient) const {
  if (slices_ == 0) {
    if (kWithGradient) gradient->setZero();
    return config_.max_distance;
  }
  const double res = geometry_.resolution;
  const AxisCell north = locate((ned.x() - geometry_.origin_north) / res - 0.5, geometry_.rows);
  const AxisCell east = locate((ned.y() - geometry_.origin_east) / res - 0.5, geometry_.cols);
  const AxisCell up = locate((-ned.z() - alt_lo_) / config_.vertical_resolution, slices_);
  ensure_slice(up.index);
  if (up.step) ensure_slice(up.index + 1);

  const std::ptrdiff_t cols = geometry_.cols;
  const std::ptrdiff_t slice = static_cast<std::ptrdiff_t>(geometry_.rows) * cols;
  const float* c000 = distance_.data() + up.index * slice + north.index * cols + east.index;
  const std::ptrdiff_t de = east.step, dn = north.step * cols, du = up.step * slice;
  // cXYZ: X = up, Y = north, Z = east offset.
  const double v000 = c000[0], v001 = c000[de], v010 = c000[dn], v011 = c000[dn + de];
  const double v100 = c000[du], v101 = c000[du + de], v110 = c000[du + dn],
               v111 = c000[du + dn + de];
  const double te = east.t, tn = north.t, tu = up.t;
  const double slope00 = v001 - v000, slope01 = v011 - v010;
  const double slope10 = v101 - v100, slope11 = v111 - v110;
  const double e00 = v000 + te * slope00, e01 = v010 + te * slope01;
  const double e10 = v100 + te * slope10, e11 = v110 + te * slope11;
  const double n0 = e00 + tn * (e01 - e00), n1 = e10 + tn * (e11 - e10);
  const double value = n0 + tu * (n1 - n0);
  if (kWithGradient) {
    const double d_up = n1 - n0;
    const double d_north = (1 - tu) * (e01 - e00) + tu * (e11 - e10);
    const double d_east =
        (1 - tu) * ((1 - tn) * slope00 + tn * slope01) + tu * ((1 - tn) * slope10 + tn * slope11);
    *gradient = Vec3(north.varies ? d_north / res : 0.0, east.varies ? d_east / res : 0.0,
                     up.varies ? -d_up / config_.vertical_resolution : 0.0);
  }
  return value;
}

DistanceSample DistanceField::query(const Vec3& ned) const {
  DistanceSample out;
  out.distance = sample<true>(ned, &out.gradient);
  return out;
}

double DistanceField::distance(const Vec3& ned) const {
  return sample<false>(ned, nullptr);
}

}  // namespace ofn::mapping
