#pragma once
// Euclidean distance from any point to the obstacles of a heightfield (every
// cell a column from the ground to its top), with a smooth (trilinear)
// interpolation and its gradient: the clearance the RH optimiser constrains
// (paper Eq. 7). Built as an exact distance transform per altitude slice:
// since obstacles are columns, the 3-D transform reduces to a 2-D lower
// envelope pass whose initial cost is the squared height above each column.

#include <vector>

#include "ofn/common/frames.hpp"
#include "ofn/mapper/heightfield.hpp"

namespace ofn::mapping {

struct DistanceFieldConfig {
  double vertical_resolution = 1.0;  // m between altitude slices
  double max_distance = 30.0;        // m; distances are clamped to this
};

struct DistanceSample {
  double distance = 0;             // m; negative inside an obstacle, by at most one cell
  Vec3 gradient = Vec3::Zero();    // d distance / d position, world NED
};

class DistanceField {
 public:
  DistanceField() = default;
  explicit DistanceField(const DistanceFieldConfig& config) : config_(config) {}

  /// Builds the field over the heightfield's footprint for altitudes
  /// [alt_lo, alt_hi] (m above ground). Cells above `occupied_above` count
  /// as obstacle columns.
  void build(const Heightfield& field, double alt_lo, double alt_hi, double occupied_above = 0.5);

  bool empty() const { return slices_ == 0; }
  /// Distance and gradient at a world NED point. Outside the built volume
  /// the nearest boundary value is used (and the gradient along the clamped
  /// axes is zero).
  DistanceSample query(const Vec3& ned) const;
  /// Distance only, same interpolation.
  double distance(const Vec3& ned) const;

 private:
  DistanceFieldConfig config_;
  Heightfield geometry_;  // top left empty; only the grid geometry is kept
  double alt_lo_ = 0;
  int slices_ = 0;
  std::vector<float> distance_;  // slices_ * rows * cols
};

}  // namespace ofn::mapping
