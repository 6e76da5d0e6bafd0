#pragma once
// Euclidean distance from any point to the obstacles of a heightfield (every
// cell a column from the ground to its top), with a smooth (trilinear)
// interpolation and its gradient: the clearance the RH optimiser constrains
// (paper Eq. 7). Built as an exact distance transform per altitude slice:
// since obstacles are columns, the 3-D transform reduces to a 2-D lower
// envelope pass whose initial cost is the squared height above each column.
//
// The grid is a sampling: horizontal distances are measured between cell
// centres, so away from an obstacle the clearance exceeds the distance to the
// cell's faces by up to half a cell (res / sqrt(2) across a corner); the
// safety radius must carry that margin. Inside a column the field is the
// negative distance to the nearest air (beside it, or above its top), so
// the sign changes half-way between an obstacle centre and a free one and the
// gradient points out.
//
// Slices are transformed on first use: a flight at one altitude queries a few
// of the band's slices, and the transform is most of the planner's work. A
// lazily built slice is the same, bit for bit, as an eagerly built one. The
// first query of a slice writes into the field, so a DistanceField is not for
// concurrent queries from several threads.

#include <vector>

#include "ofn/common/frames.hpp"
#include "ofn/map/heightfield.hpp"

namespace ofn::mapping {

struct DistanceFieldConfig {
  double vertical_resolution = 1.0;  // m between altitude slices
  double max_distance = 30.0;        // m; distances (and depths inside) are clamped to this
};

struct DistanceSample {
  double distance = 0;           // m; negative inside an obstacle
  Vec3 gradient = Vec3::Zero();  // d distance / d position, world NED
};

class DistanceField {
 public:
  DistanceField() = default;
  explicit DistanceField(const DistanceFieldConfig& config) : config_(config) {}

  /// Sets the field over the heightfield's footprint for altitudes
  /// [alt_lo, alt_hi] (m above ground; slices every vertical_resolution from
  /// alt_lo up to the first one at or above alt_hi). Cells above
  /// `occupied_above` count as obstacle columns. Each slice is transformed
  /// when a query first needs it. Throws std::invalid_argument on a
  /// non-positive resolution or max_distance, alt_hi < alt_lo, or a top
  /// vector that does not match rows * cols. A build on the same input as
  /// the last one (same geometry, band and obstacle tops) keeps the slices
  /// already transformed: they are what a fresh transform would give.
  void build(const Heightfield& field, double alt_lo, double alt_hi, double occupied_above = 0.5);
  /// Transforms every slice now (for a caller that wants the cost up front).
  void build_all_slices() const;

  bool empty() const { return slices_ == 0; }
  /// Distance and gradient at a world NED point. The interpolant spans the
  /// outermost cell centres and slices; beyond them the nearest boundary
  /// value is used (and the gradient along the clamped axes is zero). An
  /// empty field is max_distance everywhere.
  DistanceSample query(const Vec3& ned) const;
  /// Distance only, same interpolation.
  double distance(const Vec3& ned) const;

  const DistanceFieldConfig& config() const { return config_; }
  int slices() const { return slices_; }
  /// Slices transformed since the last build() whose input changed.
  int slices_built() const { return slices_built_; }
  double altitude_low() const { return alt_lo_; }

 private:
  template <bool kWithGradient>
  double sample(const Vec3& ned, Vec3* gradient) const;
  // True when build() would store exactly what it holds now.
  bool same_input(const Heightfield& field, double alt_lo, int slices, double occupied_above) const;
  // Slice k, unless it is built already.
  void ensure_slice(int k) const;
  // One slice: the exterior transform into slice_out, then the interior
  // depth over the cells still inside a column.
  void build_slice(double altitude, float* slice_out) const;

  DistanceFieldConfig config_;
  Heightfield geometry_;  // top left empty; only the grid geometry is kept
  double alt_lo_ = 0;
  double occupied_above_ = 0;
  int slices_ = 0;
  std::vector<float> tops_;             // rows * cols; -inf where free
  std::vector<float> tops_transposed_;  // cols * rows
  float min_occupied_top_ = 0;

  // Filled slice by slice as queries need them (see the class comment).
  mutable std::vector<float> distance_;    // slices_ * rows * cols
  mutable std::vector<char> slice_built_;  // per slice
  mutable int slices_built_ = 0;
  // Scratch reused across slices and builds; squared distances are in cells^2.
  mutable std::vector<float> sites_;              // rows * cols, initial cost of one transform
  mutable std::vector<float> transposed_;         // cols * rows, after the pass along rows
  mutable std::vector<float> exterior_;           // rows * cols, exterior distance of one slice
  mutable std::vector<float> reaching_exterior_;  // ... of the slices every column reaches
  mutable std::vector<float> squared_;            // rows * cols, squared exterior distance
  mutable std::vector<float> line_;               // one run of inside cells along a column
  mutable std::vector<int> envelope_site_;        // lower envelope: parabola apexes
  mutable std::vector<float> envelope_cost_;      // ... their initial costs
  mutable std::vector<float> envelope_from_;      // ... and where each starts to be lowest
  mutable bool reaching_exterior_valid_ = false;
};

}  // namespace ofn::mapping
