#pragma once
// Paper section 3.2: threshold-based blob detection on the filtered grid,
// each blob's rectangle(s) with the blob's height give cuboids for the
// global planner. A blob that fills its bounding rectangle poorly (a slanted
// wall, an L-shape) is split into smaller rectangles so that the cuboids do
// not swallow free space.

#include <functional>
#include <vector>

#include "ofn/common/frames.hpp"
#include "ofn/map/heightfield.hpp"

namespace ofn::mapping {

/// World NED, axis aligned. top_altitude = -min.z().
struct Cuboid {
  Vec3 min = Vec3::Zero();
  Vec3 max = Vec3::Zero();
  bool top_observed = true;
  double top_altitude() const { return -min.z(); }
};

struct CuboidExtractorConfig {
  double height_threshold = 1.5;  // m above ground; taller cells are obstacle cells
  double min_area = 4.0;          // m^2; smaller blobs are dropped as noise
  double min_fill = 0.6;          // split rectangles filled less than this
  double min_split_size = 4.0;    // m; rectangles are not split below this edge length
  double ground_altitude = 0;     // m
  double ceiling = 150.0;         // m above ground; top of cuboids whose top was not seen
  int max_split_depth = 8;        // bounds the halving of one blob (at most 2^depth rectangles)
};

class CuboidExtractor {
 public:
  explicit CuboidExtractor(const CuboidExtractorConfig& config) : config_(config) {}

  /// Optional check whether the space just above a rectangle's top was ever
  /// seen (arguments: the rectangle min/max corner north/east and its top
  /// altitude, i.e. ground_altitude + the cell top, as Cuboid::top_altitude()).
  /// Without it every top counts as observed.
  using TopSeen = std::function<bool(double min_north, double min_east, double max_north,
                                     double max_east, double top_altitude)>;

  /// Cuboids ordered by min north, then min east. Throws std::invalid_argument
  /// if the grid's cell count or resolution is inconsistent.
  std::vector<Cuboid> extract(const Heightfield& filtered, const TopSeen& top_seen = {}) const;

 private:
  CuboidExtractorConfig config_;
};

}  // namespace ofn::mapping
