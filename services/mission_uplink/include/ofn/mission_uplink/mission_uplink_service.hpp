#pragma once
// Ground-station uplink: reads a scenario file and publishes its waypoint
// plan and limits as MISSION, at start, once a second (for services that
// join late) and with a new mission_id whenever the file changes.

#include <filesystem>
#include <string>

#include "ofn/common/node.hpp"
#include "ofn/common/scenario.hpp"
#include "ofn/mission_t.hpp"

namespace ofn::uplink {

/// The MISSION message for a scenario (SI, world NED).
mission_t mission_from_scenario(const Scenario& scenario, int32_t mission_id);

class MissionUplinkService {
 public:
  MissionUplinkService(lcm::LCM& lcm, const Clock& clock, std::string scenario_path);
  Node& node() { return node_; }
  const mission_t& mission() const { return mission_; }

 private:
  void tick();
  void reload_if_changed();

  Node node_;
  std::string path_;
  std::filesystem::file_time_type loaded_mtime_;
  mission_t mission_;
};

}  // namespace ofn::uplink
