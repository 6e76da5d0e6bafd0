#pragma once
// What the content checks of the messages share: size bounds and finite
// numbers. Each message's check is declared in its own header,
// ofn/common/validate/<message>.hpp (ofn/common/validate.hpp has them all),
// so a service compiles only the types it receives. Each returns an empty
// string when the message is acceptable and otherwise a short reason that
// the node counts and logs. Time (staleness) is checked by the node, not
// here.

#include <cmath>
#include <cstddef>

namespace ofn {

/// Size bounds: a message larger than these is rejected as implausible.
struct MessageLimits {
  static constexpr int kMaxWaypoints = 1000;
  static constexpr int kMaxObstacles = 10000;
  static constexpr int kMaxBeams = 20000;
  static constexpr int kMaxScanPoints = 200000;
  static constexpr int kMaxGridCells = 4000000;
  static constexpr int kMaxCuboids = 10000;
  static constexpr int kMaxPathPoints = 10000;
  static constexpr int kMaxTrajSamples = 20000;
  static constexpr int kMaxSplineKnots = 1000;
  static constexpr int kMaxPassages = 1000;
  /// Positions farther than this from the origin are not from this mission.
  static constexpr double kMaxCoordinate = 1.0e6;
  /// An obstacle grid's cell edge, m: the mapper's own range (its grid
  /// resolution setting). Receivers size fields from it (the RH
  /// optimiser pads the grid by tens of metres of cells), so a cell of
  /// 1e-300 m or 1e300 m must not reach them.
  static constexpr double kMinGridResolution = 0.05;
  static constexpr double kMaxGridResolution = 20.0;
};

template <class It>
bool all_finite(It first, It last) {
  for (; first != last; ++first)
    if (!std::isfinite(static_cast<double>(*first))) return false;
  return true;
}
template <class T, size_t N>
bool all_finite(const T (&array)[N]) {
  return all_finite(array, array + N);
}

}  // namespace ofn
