#pragma once
// The mapper's core: one scan at a time into the vehicle-attached grid and
// the 3-D occupancy map; once a second, the grid is reconciled with the
// occupancy evidence (false returns fade, removed obstacles go), cuboids are
// extracted from the confirmed part of the grid and the obstacle database is
// updated. No LCM in here; MapperService binds it to the bus.

#include <cstdint>
#include <vector>

#include "ofn/common/time.hpp"
#include "ofn/common/frames.hpp"
#include "ofn/mapper/cuboid_extractor.hpp"
#include "ofn/mapper/hit_spread.hpp"
#include "ofn/mapper/obstacle_database.hpp"
#include "ofn/mapper/obstacle_grid.hpp"
#include "ofn/mapper/occupancy_map.hpp"

namespace ofn::mapping {

struct MapperConfig {
  ObstacleGridConfig grid;
  OccupancyMapConfig occupancy;
  CuboidExtractorConfig cuboids;
  ObstacleDatabaseConfig database;
  /// Use the 3-D occupancy map to retire and confirm grid cells. Off: the
  /// paper's grid alone (every hit stays forever).
  bool use_occupancy = true;
  /// Probability a voxel must reach before its column may form a cuboid:
  /// higher than the occupancy threshold so that one stray return, which
  /// the grid shows at once, needs a second hit before the planner sees it.
  double confirm_probability = 0.8;
  /// A cell's top counts as seen when a beam crossed the whole cell at most
  /// this far above it (m). Beams that end inside a cell do not count: a
  /// beam that ran out of range just in front of a wall's face says nothing
  /// about its top.
  double top_seen_band = 4.0;
  /// With top_over_hits, only when the cell's hits lie at least
  /// top_over_hits_margin (m) on each side of the beam's horizontal line
  /// (HitSpread): a beam through the free part of a cell that an obstacle's
  /// corner fills in part passes beside the corner, not over it (dense field
  /// 7: a corner proved 6.6 m lower than it is). The margin is more than the
  /// scatter of hits on one vertical edge, less than that of hits across a
  /// face. Off by default: with it, more tops stay unproven and stand at the
  /// ceiling, and on 30 dense fields the vehicle stopped far more often
  /// (docs/RESULTS.md).
  bool top_over_hits = false;
  double top_over_hits_margin = 0.05;
};

struct ScanInput {
  Utime utime = 0;
  Vec3 sensor_origin = Vec3::Zero();  // world NED
  std::vector<Vec3> points;           // hits, world NED
  std::vector<Vec3> free_ray_ends;    // ends of beams without a return, world NED
};

struct MapperCounters {
  int64_t scans = 0;
  int64_t points = 0;         // hits landed on the grid
  int64_t cells_lowered = 0;  // grid cells the occupancy map lowered or cleared
  int64_t cycles = 0;         // cuboid cycles
};

class Mapper {
 public:
  explicit Mapper(const MapperConfig& config);

  /// Moves the grid with the vehicle.
  void set_vehicle_position(const Vec3& ned);
  void add_scan(const ScanInput& scan);
  /// One cuboid cycle (1 Hz): reconcile, extract, update the database.
  void update_cuboids(Utime now);

  const MapperConfig& config() const { return config_; }
  /// The smoothed, inflated grid (OBSTACLE_GRID). A cell whose top no beam
  /// has passed over, on it or on the surface it belongs to, stands at the
  /// ceiling: the scanner saw its face up to where it stopped looking, not
  /// where the obstacle ends.
  const Heightfield& grid();
  const Heightfield& raw_grid() const { return grid_.raw(); }
  const std::vector<ObstacleEntry>& obstacles() const { return database_.entries(); }
  const std::vector<Cuboid>& last_extraction() const { return extracted_; }
  const OccupancyMap& occupancy() const { return occupancy_; }
  const MapperCounters& counters() const { return counters_; }
  const ObstacleDatabase& database() const { return database_; }

 private:
  /// Calls visit(row, col, top, occupied_top) for every occupied grid
  /// cell, with the highest voxel top of its column that reaches
  /// min_probability (negative: none).
  template <class Visit>
  void for_each_column_top(double min_probability, Visit visit) const;
  void reconcile_with_occupancy();
  Heightfield confirmed_grid();
  /// Marks the cells whose top the beam from `origin` to `end` passed over
  /// and went on past by `min_continuation` cells.
  void trace_over_tops(const Vec3& origin, const Vec3& end, double min_continuation,
                       std::vector<Vec3>& seen_points) const;
  bool rectangle_top_seen(double min_n, double min_e, double max_n, double max_e, double top) const;

  MapperConfig config_;
  ObstacleGrid grid_;
  Heightfield published_;  // OBSTACLE_GRID: the filtered grid with unseen tops at the ceiling
  struct KnownTop {
    int row, col;
    float seen_top;  // the top a beam went over, where the surface was found
  };
  std::vector<uint8_t> top_known_;  // scratch, per raw cell
  std::vector<KnownTop> frontier_;  // scratch
  ObstacleGrid confirmed_;          // scratch: the grid's confirmed cells, inflated and smoothed
  // Per cell, the highest top a beam has been seen to pass over (same
  // geometry as grid_, moved with it).
  ObstacleGrid seen_over_;
  // Where in each cell the hits lie: a look over a top must cross them.
  HitSpread hit_spread_;
  std::vector<Vec3> seen_points_;  // scratch
  OccupancyMap occupancy_;
  CuboidExtractor extractor_;
  ObstacleDatabase database_;
  Vec3 vehicle_ = Vec3::Zero();
  std::vector<Cuboid> extracted_;
  MapperCounters counters_;
};

}  // namespace ofn::mapping
