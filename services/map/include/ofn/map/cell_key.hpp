#pragma once
// World-fixed horizontal cells as hash keys: the records of what the LIDAR
// has crossed or hit keep cells by these, so they stay put while the
// vehicle-attached grid moves.

#include <cmath>
#include <cstdint>
#include <utility>

namespace ofn::mapping {

/// Key of the `resolution` square cell holding (north, east).
inline int64_t cell_key(double north, double east, double resolution) {
  const auto row = static_cast<int64_t>(std::floor(north / resolution));
  const auto col = static_cast<int64_t>(std::floor(east / resolution));
  return static_cast<int64_t>(static_cast<uint64_t>(row) << 32) ^ (col & 0xffffffffLL);
}

/// Centre (north, east) of the cell a key names.
inline std::pair<double, double> cell_key_centre(int64_t key, double resolution) {
  const int64_t row = key >> 32;
  const auto col = static_cast<int32_t>(key & 0xffffffffLL);
  return {(static_cast<double>(row) + 0.5) * resolution,
          (static_cast<double>(col) + 0.5) * resolution};
}

}  // namespace ofn::mapping
