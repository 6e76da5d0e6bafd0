#include "ofn/mission_uplink/mission_uplink_service.hpp"

#include "ofn/common/channels.hpp"
#include "ofn/common/config.hpp"

namespace ofn::uplink {

mission_t mission_from_scenario(const Scenario& s, int32_t mission_id) {
  mission_t m;
  m.utime = 0;
  m.mission_id = mission_id;
  m.name = s.name;
  m.frame = "NED";
  m.cruise_speed = s.cruise_speed;
  m.limits.max_speed = s.limits.max_speed;
  m.limits.max_accel = s.limits.max_accel;
  m.limits.max_vertical_speed = s.limits.max_vertical_speed;
  m.limits.min_forward_speed = s.limits.min_forward_speed;
  m.limits.clearance = s.limits.clearance;
  m.limits.sensor_range = s.limits.sensor_range;
  for (const auto& w : s.waypoints) {
    waypoint_t wp;
    for (int i = 0; i < 3; ++i) wp.position[i] = w.position[i];
    wp.capture_radius = w.capture_radius;
    m.waypoints.push_back(wp);
  }
  m.num_waypoints = static_cast<int32_t>(m.waypoints.size());
  return m;
}

MissionUplinkService::MissionUplinkService(lcm::LCM& lcm, const Clock& clock,
                                           std::string scenario_path)
    : node_("mission_uplink", lcm, clock), path_(std::move(scenario_path)) {
  // A bad file at start is fatal (ConfigError reaches main); later edits
  // that break the file keep the last good plan flying.
  mission_ = mission_from_scenario(load_scenario(path_), 1);
  loaded_mtime_ = std::filesystem::last_write_time(path_);
  node_.set_state("running");
  node_.add_timer(
      1.0, [this] { tick(); }, "uplink");
}

void MissionUplinkService::reload_if_changed() {
  std::error_code ec;
  const auto mtime = std::filesystem::last_write_time(path_, ec);
  if (ec || mtime == loaded_mtime_) return;
  loaded_mtime_ = mtime;
  try {
    mission_ = mission_from_scenario(load_scenario(path_), mission_.mission_id + 1);
    node_.log().info("{} changed: uplinking mission {}", path_, mission_.mission_id);
    node_.set_state("running");
  } catch (const ConfigError& e) {
    node_.log().error("{} changed but cannot be used, keeping mission {}: {}", path_,
                      mission_.mission_id, e.what());
    node_.set_state("degraded");
  }
}

void MissionUplinkService::tick() {
  reload_if_changed();
  mission_.utime = node_.now();
  node_.publish(channels::kMission, mission_);
}

}  // namespace ofn::uplink
