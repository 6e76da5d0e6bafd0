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

#include <vector>

#include "ofn/common/frames.hpp"
#include "ofn/mapper/heightfield.hpp"

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

  /// Builds the field over the heightfield's footprint for altitudes
  /// [alt_lo, alt_hi] (m above ground; slices every vertical_resolution from
  /// alt_lo up to the first one at or above alt_hi). Cells above
  /// `occupied_above` count as obstacle columns. Throws std::invalid_argument
  /// on a non-positive resolution or max_distance, alt_hi < alt_lo, or a top
  /// vector that does not match rows * cols.
  void build(const Heightfield& field, double alt_lo, double alt_hi, double occupied_above = 0.5);

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
  double altitude_low() const { return alt_lo_; }

 private:
  template <bool kWithGradient>
  double sample(const Vec3& ned, Vec3* gradient) const;
  // One slice: the exterior transform into slice_out, then the interior
  // depth over the cells still inside a column.
  void build_slice(double altitude, float* slice_out);

  DistanceFieldConfig config_;
  Heightfield geometry_;  // top left empty; only the grid geometry is kept
  double alt_lo_ = 0;
  int slices_ = 0;
  std::vector<float> distance_;  // slices_ * rows * cols

  // Scratch reused across builds; squared distances are in cells^2.
  std::vector<float> tops_;             // rows * cols; -inf where free
  std::vector<float> sites_;            // rows * cols, initial cost of one transform
  std::vector<float> transposed_;       // cols * rows, after the pass along rows
  std::vector<float> exterior_;         // rows * cols, exterior distance of the last slice
  std::vector<float> tops_transposed_;  // cols * rows
  std::vector<float> squared_;          // rows * cols, squared exterior distance
  std::vector<float> line_;             // one run of inside cells along a column
  std::vector<int> envelope_site_;      // lower envelope: parabola apexes
  std::vector<float> envelope_cost_;    // ... their initial costs
  std::vector<float> envelope_from_;    // ... and where each starts to be lowest
  float min_occupied_top_ = 0;
  bool exterior_valid_ = false;  // exterior_ holds the slices every column reaches
};

}  // namespace ofn::mapping
