#pragma once
// Where in each grid cell the LIDAR has hit something, so that a beam that
// passes over a cell's top can be told from one that passes beside it.
//
// A cell is 1 m across; an obstacle may fill only part of it. At a box's
// corner, seen only at the edge of the sweep, the beams that hit the corner
// stop at some height and the beams just above them in the same scan pass
// beside the corner through the free part of its cell, not over its top.
// Counting those as looks over the top proved the corner 6.6 m lower than it
// is (dense field 7, passed at 0.5 R_s). A beam has passed over the part of
// the cell that holds the obstacle only if the cell's hits lie on both sides
// of its horizontal line.
//
// Per cell the record keeps the extreme hits in eight horizontal directions:
// real hit points, so a cell whose hits all lie on one side of a line keeps
// only points on that side. Pure core: world NED, metres, cells world-fixed.

#include <array>
#include <cstdint>
#include <unordered_map>

#include "ofn/common/frames.hpp"

namespace ofn::mapping {

class HitSpread {
 public:
  explicit HitSpread(double resolution = 1.0);

  /// One hit (world NED); non-finite points are ignored.
  void add(const Vec3& hit);
  /// Whether the horizontal line through `from` and `to` has hits of the
  /// cell at (north, east) at least `margin` m on each side of it. A cell
  /// with no hit recorded answers true: nothing says the line passed beside.
  bool straddled(double north, double east, const Vec3& from, const Vec3& to, double margin) const;
  /// Drops cells farther than `radius` horizontally from `centre`.
  void forget_beyond(const Vec3& centre, double radius);
  size_t size() const { return cells_.size(); }

 private:
  static constexpr int kDirections = 8;
  struct Extremes {
    std::array<float, 2 * kDirections> north_east;  // (north, east) per direction
    std::array<float, kDirections> reach;           // the extreme's projection
  };
  int64_t key(double north, double east) const;

  double resolution_;
  std::unordered_map<int64_t, Extremes> cells_;
};

}  // namespace ofn::mapping
