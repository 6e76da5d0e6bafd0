#include "ofn/obstacle_injector/obstacle_injector_service.hpp"

#include <algorithm>
#include <iterator>

#include "ofn/common/channels.hpp"
#include "ofn/common/obstacle_messages.hpp"
#include "ofn/common/validate.hpp"

namespace ofn::injector {
namespace {

Scenario load_obstacles(const std::string& path) {
  Scenario s = load_scenario(path);
  if (s.obstacles.size() > static_cast<size_t>(MessageLimits::kMaxObstacles))
    throw ConfigError(path + ": field 'obstacles': more than " +
                      std::to_string(MessageLimits::kMaxObstacles) +
                      " obstacles (the VIRTUAL_OBSTACLES limit)");
  return s;
}

std::string id_list(const std::vector<int>& ids) {
  if (ids.empty()) return "none";
  std::string out;
  for (int id : ids) out += (out.empty() ? "" : ", ") + std::to_string(id);
  return out;
}

}  // namespace

ObstacleInjectorConfig load_obstacle_injector_config(YamlReader& r) {
  ObstacleInjectorConfig c;
  c.publish_period = r.number_in("publish_period", c.publish_period, 0.01, 3600.0);
  c.check_rate = r.number_in("check_rate_hz", c.check_rate, 0.1, 1000.0);
  r.finish();
  return c;
}

ObstacleInjectorService::ObstacleInjectorService(lcm::LCM& lcm, const Clock& clock,
                                                 std::string scenario_path,
                                                 ObstacleInjectorConfig config)
    : node_("obstacle_injector", lcm, clock), path_(std::move(scenario_path)), config_(config) {
  // A bad file at start is fatal (ConfigError reaches main); later edits
  // that break the file keep the last good obstacles.
  scenario_ = load_obstacles(path_);
  loaded_mtime_ = std::filesystem::last_write_time(path_);
  node_.set_state("running");
  node_.add_timer(
      1.0 / config_.check_rate, [this] { check(); }, "check");
}

double ObstacleInjectorService::mission_time() const {
  return mission_start_ == INT64_MIN ? 0.0 : to_seconds(node_.now() - mission_start_);
}

bool ObstacleInjectorService::reload_if_changed() {
  std::error_code ec;
  const auto mtime = std::filesystem::last_write_time(path_, ec);
  if (ec || mtime == loaded_mtime_) return false;
  loaded_mtime_ = mtime;
  try {
    scenario_ = load_obstacles(path_);
    node_.log().info("{} changed: {} obstacles loaded", path_, scenario_.obstacles.size());
    node_.set_state("running");
    return true;
  } catch (const ConfigError& e) {
    node_.log().error("{} changed but cannot be used, keeping revision {}: {}", path_, revision_,
                      e.what());
    node_.set_state("degraded");
    return false;
  }
}

void ObstacleInjectorService::check() {
  const Utime now = node_.now();
  if (mission_start_ == INT64_MIN) mission_start_ = now;
  const bool first = revision_ == 0;
  const bool reloaded = reload_if_changed();

  const double t = to_seconds(now - mission_start_);
  std::vector<int> ids;
  for (const auto& o : scenario_.obstacles)
    if (o.present_at(t)) ids.push_back(o.id);
  std::sort(ids.begin(), ids.end());

  const bool set_changed = ids != present_ids_;
  if (set_changed || first) {
    std::vector<int> appeared, disappeared;
    std::set_difference(ids.begin(), ids.end(), present_ids_.begin(), present_ids_.end(),
                        std::back_inserter(appeared));
    std::set_difference(present_ids_.begin(), present_ids_.end(), ids.begin(), ids.end(),
                        std::back_inserter(disappeared));
    node_.log().info("t = {:.2f} s: obstacles appeared: {}; disappeared: {}; present: {}", t,
                     id_list(appeared), id_list(disappeared), id_list(ids));
  }
  present_ids_ = std::move(ids);

  if (first || set_changed || reloaded) {
    ++revision_;
    publish();
  } else if (now - last_publish_ >= to_utime(config_.publish_period)) {
    publish();
  }
}

void ObstacleInjectorService::publish() {
  virtual_obstacles_t msg;
  msg.utime = node_.now();
  msg.revision = revision_;
  msg.ground_altitude = scenario_.ground_altitude;
  for (const auto& o : scenario_.obstacles)
    if (std::binary_search(present_ids_.begin(), present_ids_.end(), o.id))
      msg.obstacles.push_back(to_message(o));
  msg.num_obstacles = static_cast<int32_t>(msg.obstacles.size());
  node_.publish(channels::kVirtualObstacles, msg);
  last_publish_ = msg.utime;
}

}  // namespace ofn::injector
