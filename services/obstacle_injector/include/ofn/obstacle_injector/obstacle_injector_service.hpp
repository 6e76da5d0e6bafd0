#pragma once
// Ground-station virtual obstacles: reads a scenario file and publishes the
// obstacles present at the current mission time as VIRTUAL_OBSTACLES, at
// once whenever the present set or the file changes (with a new revision)
// and again every publish period for services that join late.

#include <filesystem>
#include <string>
#include <vector>

#include "ofn/common/config.hpp"
#include "ofn/common/node.hpp"
#include "ofn/common/scenario.hpp"
#include "ofn/virtual_obstacles_t.hpp"

namespace ofn::injector {

struct ObstacleInjectorConfig {
  double publish_period = 1.0;  // s between re-sends of an unchanged set
  double check_rate = 20.0;     // Hz; schedule and file checks, so the pop-up latency
};

/// Reads the config fields (all optional); throws ConfigError naming the field.
ObstacleInjectorConfig load_obstacle_injector_config(YamlReader& reader);

class ObstacleInjectorService {
 public:
  /// A bad scenario at start throws ConfigError; later bad edits keep the
  /// last good obstacles.
  ObstacleInjectorService(lcm::LCM& lcm, const Clock& clock, std::string scenario_path,
                          ObstacleInjectorConfig config = {});
  Node& node() { return node_; }

  /// Increments on every change of the published set or accepted file edit;
  /// 0 before the first check.
  int32_t revision() const { return revision_; }
  /// Ids of the obstacles present at the last check, ascending.
  const std::vector<int>& present_ids() const { return present_ids_; }
  /// Seconds since the first check; 0 before it.
  double mission_time() const;
  const Scenario& scenario() const { return scenario_; }

 private:
  void check();
  bool reload_if_changed();
  void publish();

  Node node_;
  std::string path_;
  ObstacleInjectorConfig config_;
  Scenario scenario_;
  std::filesystem::file_time_type loaded_mtime_;
  Utime mission_start_ = INT64_MIN;
  Utime last_publish_ = INT64_MIN;
  int32_t revision_ = 0;
  std::vector<int> present_ids_;
};

}  // namespace ofn::injector
