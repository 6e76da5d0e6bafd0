#pragma once
// The obstacle database (paper section 3.2, Fig. 6). Each cycle's extraction
// from the current grid is the best knowledge of the area the grid covers:
// an extracted cuboid that overlaps an entry updates it (keeping its id),
// one that overlaps several entries merges them, one that overlaps none is
// inserted; an entry in view that no extraction matches is missed and, after
// a few misses, retired. Entries out of view (left behind by the
// vehicle-attached grid) are kept as they are.

#include <cstdint>
#include <functional>
#include <vector>

#include "ofn/common/time.hpp"
#include "ofn/mapper/cuboid_extractor.hpp"

namespace ofn::mapping {

struct ObstacleDatabaseConfig {
  double match_overlap = 0.3;   // footprint overlap, as a fraction of the smaller one, that matches
  int retire_after_misses = 2;  // cycles in view but not found before an entry is removed
  double confidence_step = 0.25;  // confidence gained per sighting (lost per miss)
};

struct ObstacleEntry {
  int id = 0;
  Cuboid cuboid;
  double confidence = 0;  // 0..1
  Utime first_seen = 0;
  Utime last_seen = 0;
  int misses = 0;
};

/// Intersection area of the two north/east footprints divided by the smaller
/// footprint's area; 0 if either footprint has no area.
double footprint_overlap(const Cuboid& a, const Cuboid& b);

class ObstacleDatabase {
 public:
  explicit ObstacleDatabase(const ObstacleDatabaseConfig& config) : config_(config) {}

  /// One cycle. `in_view` tells whether a database entry's footprint lies
  /// where the current grid/sensor could have seen it: only such entries can
  /// be missed (and retired); the others are kept as they are. An empty
  /// `in_view` counts every entry as in view.
  void update(const std::vector<Cuboid>& extracted, Utime now,
              const std::function<bool(const Cuboid&)>& in_view);

  const std::vector<ObstacleEntry>& entries() const { return entries_; }
  int inserted() const { return inserted_; }
  int retired() const { return retired_; }
  /// Entries absorbed into a lower-id entry that one extracted cuboid matched
  /// together with them.
  int merged() const { return merged_; }
  void clear() { entries_.clear(); }

 private:
  ObstacleDatabaseConfig config_;
  std::vector<ObstacleEntry> entries_;
  int next_id_ = 1;
  int inserted_ = 0;
  int retired_ = 0;
  int merged_ = 0;
};

}  // namespace ofn::mapping
