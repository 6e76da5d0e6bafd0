#include "ofn/map/heightfield.hpp"

#include <cmath>
#include <limits>

namespace ofn::mapping {

namespace {

// Far-away or non-finite coordinates must still give a well-defined index
// outside the grid rather than an out-of-range float-to-int conversion.
int clamped_index(double cells) {
  constexpr double kLimit = std::numeric_limits<int>::max() / 2;
  if (!(cells > -kLimit)) return static_cast<int>(-kLimit);
  if (cells > kLimit) return static_cast<int>(kLimit);
  return static_cast<int>(std::floor(cells));
}

}  // namespace

int Heightfield::row_of(double north) const {
  return clamped_index((north - origin_north) / resolution);
}

int Heightfield::col_of(double east) const {
  return clamped_index((east - origin_east) / resolution);
}

}  // namespace ofn::mapping
