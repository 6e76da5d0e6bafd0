#include "ofn/mapper/hit_spread.hpp"

#include <cmath>
#include <iterator>
#include <limits>
#include <stdexcept>

#include "ofn/map/cell_key.hpp"

namespace ofn::mapping {
namespace {

// Unit vectors of the eight directions, 45 deg apart.
constexpr double kHalfSqrt2 = 0.70710678118654752;
constexpr double kDirNorth[8] = {1, kHalfSqrt2, 0, -kHalfSqrt2, -1, -kHalfSqrt2, 0, kHalfSqrt2};
constexpr double kDirEast[8] = {0, kHalfSqrt2, 1, kHalfSqrt2, 0, -kHalfSqrt2, -1, -kHalfSqrt2};

}  // namespace

HitSpread::HitSpread(double resolution) : resolution_(resolution) {
  if (!(resolution > 0) || !std::isfinite(resolution))
    throw std::invalid_argument("HitSpread: resolution must be > 0");
}

int64_t HitSpread::key(double north, double east) const {
  return cell_key(north, east, resolution_);
}

void HitSpread::add(const Vec3& hit) {
  if (!std::isfinite(hit.x()) || !std::isfinite(hit.y()) || !std::isfinite(hit.z())) return;
  auto [it, inserted] = cells_.try_emplace(key(hit.x(), hit.y()));
  Extremes& e = it->second;
  if (inserted) e.reach.fill(-std::numeric_limits<float>::infinity());
  for (int d = 0; d < kDirections; ++d) {
    const auto along = static_cast<float>(hit.x() * kDirNorth[d] + hit.y() * kDirEast[d]);
    if (along > e.reach[d]) {
      e.reach[d] = along;
      e.north_east[2 * d] = static_cast<float>(hit.x());
      e.north_east[2 * d + 1] = static_cast<float>(hit.y());
    }
  }
}

bool HitSpread::straddled(double north, double east, const Vec3& from, const Vec3& to,
                          double margin) const {
  const auto it = cells_.find(key(north, east));
  if (it == cells_.end()) return true;
  const double dn = to.x() - from.x(), de = to.y() - from.y();
  const double length = std::hypot(dn, de);
  if (!(length > 0)) return false;
  // Signed distance of each extreme hit from the line (left positive).
  bool left = false, right = false;
  for (int d = 0; d < kDirections; ++d) {
    const double pn = it->second.north_east[2 * d] - from.x();
    const double pe = it->second.north_east[2 * d + 1] - from.y();
    const double side = (dn * pe - de * pn) / length;
    left = left || side >= margin;
    right = right || side <= -margin;
  }
  return left && right;
}

void HitSpread::forget_beyond(const Vec3& centre, double radius) {
  const double r2 = radius * radius;
  for (auto it = cells_.begin(); it != cells_.end();) {
    const auto [north, east] = cell_key_centre(it->first, resolution_);
    const double dn = north - centre.x(), de = east - centre.y();
    it = dn * dn + de * de > r2 ? cells_.erase(it) : std::next(it);
  }
}

}  // namespace ofn::mapping
