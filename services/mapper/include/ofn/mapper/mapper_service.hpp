#pragma once
// Binds the mapper core to the bus: SCAN_WORLD and NAV_STATE in; the
// obstacle grid (OBSTACLE_GRID) out after every scan and the obstacle
// database (CUBOIDS) once a second.

#include "ofn/common/config.hpp"
#include "ofn/common/node.hpp"
#include "ofn/cuboid_list_t.hpp"
#include "ofn/mapper/mapper.hpp"
#include "ofn/nav_state_t.hpp"
#include "ofn/obstacle_grid_t.hpp"
#include "ofn/scan_world_t.hpp"

namespace ofn::mapping {

struct MapperServiceConfig {
  MapperConfig mapper;
  double cuboid_rate = 1.0;   // Hz, obstacle database cycle and CUBOIDS
  double scan_max_age = 0.5;  // s; older SCAN_WORLD is stale
  double nav_max_age = 0.5;   // s
  /// OBSTACLE_GRID carries only the rectangle around the occupied cells,
  /// widened by this many cells, to keep the message small.
  int grid_crop_border = 4;
};

/// Reads a mapper config; unknown fields are errors.
MapperServiceConfig load_mapper_config(YamlReader& reader);

/// The occupied part of a heightfield (plus a border) as OBSTACLE_GRID; a
/// single free cell at the centre when nothing is occupied.
obstacle_grid_t grid_message(const Heightfield& field, double safety_margin, int border,
                             Utime utime);
cuboid_list_t cuboid_message(const std::vector<ObstacleEntry>& entries, Utime utime);

class MapperService {
 public:
  MapperService(lcm::LCM& lcm, const Clock& clock, MapperServiceConfig config);
  Node& node() { return node_; }
  const Mapper& mapper() const { return mapper_; }
  int64_t scans_dropped_out_of_order() const { return out_of_order_; }

 private:
  void on_scan(const scan_world_t& msg);
  void on_nav(const nav_state_t& msg);
  void cuboid_cycle();

  Node node_;
  MapperServiceConfig config_;
  Mapper mapper_;
  Utime last_scan_utime_ = INT64_MIN;
  int64_t out_of_order_ = 0;
  ScanInput scan_;  // reused buffer
};

}  // namespace ofn::mapping
