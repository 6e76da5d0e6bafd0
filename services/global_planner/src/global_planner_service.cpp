#include "ofn/global_planner/global_planner_service.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "ofn/common/channels.hpp"
#include "ofn/common/message_names.hpp"
#include "ofn/common/validate/control_status.hpp"
#include "ofn/common/validate/cuboid_list.hpp"
#include "ofn/common/validate/mission.hpp"
#include "ofn/common/validate/narrow_passages.hpp"
#include "ofn/common/validate/nav_state.hpp"

namespace ofn::planning {
namespace {

int8_t status_code(PlanStatus s) {
  switch (s) {
    case PlanStatus::kOk:
      return global_path_t::OK;
    case PlanStatus::kStartInside:
      return global_path_t::START_INSIDE_OBSTACLE;
    case PlanStatus::kGoalInside:
      return global_path_t::GOAL_INSIDE_OBSTACLE;
    case PlanStatus::kNoPath:
      break;
  }
  return global_path_t::NO_PATH;
}

// Two obstacle sets are the same when every cuboid kept its id and moved
// less than this: the mapper re-fits boxes every cycle by a cell or so.
constexpr double kSameCuboidTolerance = 0.5;  // m

bool same_cuboids(const cuboid_list_t& a, const cuboid_list_t& b) {
  if (a.cuboids.size() != b.cuboids.size()) return false;
  for (size_t i = 0; i < a.cuboids.size(); ++i) {
    const auto& x = a.cuboids[i];
    const auto& y = b.cuboids[i];
    if (x.id != y.id || x.top_observed != y.top_observed) return false;
    for (int k = 0; k < 3; ++k)
      if (std::abs(x.min_corner[k] - y.min_corner[k]) > kSameCuboidTolerance ||
          std::abs(x.max_corner[k] - y.max_corner[k]) > kSameCuboidTolerance)
        return false;
  }
  return true;
}

}  // namespace

GlobalPlannerServiceConfig load_global_planner_config(YamlReader& r) {
  GlobalPlannerServiceConfig c;
  c.replan_rate = r.number_in("replan_rate_hz", c.replan_rate, 0.05, 50.0);
  c.nav_max_age = r.number_in("nav_max_age", c.nav_max_age, 0.01, 10.0);
  c.cuboids_max_age = r.number_in("cuboids_max_age", c.cuboids_max_age, 0.1, 60.0);
  c.merge_distance = r.number_in("merge_distance", c.merge_distance, 0.0, 100.0);
  c.ground_altitude = r.number_in("ground_altitude", c.ground_altitude, -1e4, 1e4);
  c.min_altitude = r.number_in("min_altitude", c.min_altitude, 0.0, 1e4);
  c.max_altitude = r.number_in("max_altitude", c.max_altitude, 1.0, 1e4);
  if (c.max_altitude <= c.min_altitude) r.fail("max_altitude", "must be above min_altitude");
  c.path_spacing = r.number_in("path_spacing", c.path_spacing, 0.1, 100.0);
  c.collision_tolerance = r.number_in("collision_tolerance", c.collision_tolerance, 0.0, 5.0);
  c.max_obstacles = r.integer("max_obstacles", c.max_obstacles);
  if (c.max_obstacles < 1 || c.max_obstacles > 100000)
    r.fail("max_obstacles", "expected 1..100000");
  c.time_cost = r.boolean("time_cost", c.time_cost);
  r.finish();
  return c;
}

GlobalPlannerConfig planner_config_for(const GlobalPlannerServiceConfig& s, const mission_t& m) {
  GlobalPlannerConfig c;
  c.clearance = m.limits.clearance;
  c.max_accel = m.limits.max_accel;
  c.speed = std::min(m.cruise_speed, m.limits.max_speed);
  c.vertical_speed = s.time_cost ? m.limits.max_vertical_speed : 0.0;
  c.merge_distance = s.merge_distance;
  c.ground_altitude = s.ground_altitude;
  c.min_altitude = s.min_altitude;
  c.max_altitude = s.max_altitude;
  c.path_spacing = s.path_spacing;
  c.collision_tolerance = s.collision_tolerance;
  c.max_obstacles = s.max_obstacles;
  return c;
}

std::vector<ObstacleBox> boxes_from(const cuboid_list_t& msg) {
  std::vector<ObstacleBox> boxes;
  boxes.reserve(msg.cuboids.size());
  for (const auto& c : msg.cuboids)
    boxes.push_back({c.id, to_vec3(c.min_corner), to_vec3(c.max_corner), c.top_observed != 0});
  return boxes;
}

std::vector<NoGoZone> zones_from(const narrow_passages_t& msg) {
  std::vector<NoGoZone> zones;
  zones.reserve(msg.centre.size());
  for (size_t i = 0; i < msg.centre.size(); ++i)
    zones.push_back({Vec3(msg.centre[i][0], msg.centre[i][1], msg.centre[i][2]), msg.radius[i],
                     msg.half_height[i]});
  return zones;
}

global_path_t path_message(const PlanResult& result, Utime utime, const PlanResult* geometric_route,
                           const PlanResult* backtrack_route) {
  global_path_t m;
  m.utime = utime;
  m.frame = "NED";
  m.status = status_code(result.status);
  const bool geometric = result.status == PlanStatus::kNoPath && geometric_route &&
                         geometric_route->status == PlanStatus::kOk;
  const bool backtrack = result.status == PlanStatus::kNoPath && !geometric && backtrack_route &&
                         backtrack_route->status == PlanStatus::kOk;
  if (backtrack) m.status = global_path_t::BACKTRACK;
  const PlanResult& shown = geometric ? *geometric_route : backtrack ? *backtrack_route : result;
  m.cost = std::isfinite(shown.cost) ? shown.cost : -1.0;
  m.num_points = static_cast<int32_t>(shown.path.size());
  for (const auto& p : shown.path) m.points.push_back({p.x(), p.y(), p.z()});
  return m;
}

GlobalPlannerService::GlobalPlannerService(lcm::LCM& lcm, const Clock& clock,
                                           GlobalPlannerServiceConfig config)
    : node_("global_planner", lcm, clock), config_(std::move(config)) {
  node_.subscribe<nav_state_t>(
      channels::kNavState, [this](const nav_state_t& m) { on_nav(m); },
      SubscribeOptions{config_.nav_max_age, 0.5});
  // A plan is not state: it stays valid however old its stamp is.
  node_.subscribe<mission_t>(
      channels::kMission, [this](const mission_t& m) { on_mission(m); },
      SubscribeOptions{0.0, 0.0});
  node_.subscribe<cuboid_list_t>(
      channels::kCuboids, [this](const cuboid_list_t& m) { on_cuboids(m); },
      SubscribeOptions{config_.cuboids_max_age, 0.5});
  // The controller's leg moves this one on (LegTracker::follow); on_nav
  // replans for the new target.
  node_.subscribe<control_status_t>(
      channels::kControlStatus,
      [this](const control_status_t& m) { legs_.follow(m.mission_id, m.active_waypoint); },
      SubscribeOptions{config_.nav_max_age, 0.5});
  // The whole list of the mission each time, whatever its age: a passage
  // found narrow stays narrow.
  node_.subscribe<narrow_passages_t>(
      channels::kNarrowPassages, [this](const narrow_passages_t& m) { on_passages(m); },
      SubscribeOptions{0.0, 1.0});
  node_.add_timer(
      1.0 / config_.replan_rate, [this] { replan("periodic"); }, "replan");
  node_.set_state("waiting for mission, nav and cuboids");
}

void GlobalPlannerService::on_nav(const nav_state_t& m) {
  nav_ = m;
  if (!legs_.has_plan()) return;
  const auto leg = legs_.update(to_vec3(m.position));
  if (leg && leg->index != active_leg_) {
    active_leg_ = leg->index;
    replan("new target waypoint");
  }
}

void GlobalPlannerService::on_mission(const mission_t& m) {
  // The uplink repeats the plan; only a new id is a new plan.
  if (mission_ && same_plan(*mission_, m)) return;
  if (m.waypoints.empty()) {
    node_.reject(channels::kMission, "no waypoints");
    return;
  }
  mission_ = m;
  planner_.emplace(planner_config_for(config_, m));
  GlobalPlannerConfig geometric = planner_->config();
  geometric.max_accel = std::numeric_limits<double>::max();
  geometric_planner_.emplace(geometric);
  legs_.clear();
  active_leg_ = -1;
  no_go_.clear();
  node_.log().info("mission {} '{}': clearance {:.2f} m, accel {:.3f} m/s^2, speed {:.2f} m/s",
                   m.mission_id, printable(m.name), planner_->config().clearance,
                   planner_->config().max_accel, planner_->config().speed);
  replan("new mission");
}

void GlobalPlannerService::on_cuboids(const cuboid_list_t& m) {
  const bool changed = !cuboids_ || !same_cuboids(*cuboids_, m);
  cuboids_ = m;
  if (changed) replan("cuboid set changed");
}

void GlobalPlannerService::on_passages(const narrow_passages_t& m) {
  // Passages of another mission (an old one, or one this service has not
  // heard yet) say nothing about this one.
  if (!mission_ || m.mission_id != mission_->mission_id) return;
  std::vector<NoGoZone> zones = zones_from(m);
  const bool changed =
      zones.size() != no_go_.size() ||
      !std::equal(zones.begin(), zones.end(), no_go_.begin(), [](const auto& a, const auto& b) {
        return a.centre == b.centre && a.radius == b.radius && a.half_height == b.half_height;
      });
  if (!changed) return;
  no_go_ = std::move(zones);
  node_.log().info("{} passage(s) the optimiser cannot fly through", no_go_.size());
  replan("narrow passages changed");
}

void GlobalPlannerService::replan(const char* why) {
  const Utime now = node_.now();
  if (!mission_ || !planner_ || !nav_ || !cuboids_) return;
  if (now - nav_->utime > to_utime(config_.nav_max_age)) {
    node_.set_state("nav stale");
    return;
  }
  if (now - cuboids_->utime > to_utime(config_.cuboids_max_age)) {
    node_.set_state("cuboids stale");
    return;
  }
  const Vec3 position = to_vec3(nav_->position);
  if (!legs_.has_plan()) legs_.set_plan(mission_->mission_id, waypoints_from(*mission_), position);
  const auto leg = legs_.update(position);
  if (!leg) return;
  active_leg_ = leg->index;

  PlanRequest request;
  request.start = position;
  request.start_velocity = to_vec3(nav_->velocity);
  request.goal = leg->to;
  request.leg_from = leg->from;
  request.obstacles = boxes_from(*cuboids_);
  request.no_go = no_go_;
  PlanResult result = planner_->plan(request);
  std::optional<PlanResult> geometric, backtrack;
  if (result.status == PlanStatus::kNoPath) geometric = geometric_planner_->plan(request);
  // No way on along the leg: is there one back out (a dead end)?
  if (result.status == PlanStatus::kNoPath && geometric->status != PlanStatus::kOk)
    backtrack = planner_->plan_any_direction(request);
  const bool backtracks = backtrack && backtrack->status == PlanStatus::kOk;
  if (backtracks && !last_backtracks_)
    node_.log().warn("only a route that turns back exists ({}): {:.1f} m over {} nodes", why,
                     backtrack->cost, backtrack->waypoints.size());
  last_backtracks_ = backtracks;
  ++plans_;
  const bool status_changed = !last_plan_ || last_plan_->status != result.status;
  if (status_changed && result.status != PlanStatus::kOk)
    node_.log().warn("{} ({}): {} cuboids, {} nodes", to_string(result.status), why,
                     request.obstacles.size(), result.nodes);
  else if (status_changed)
    node_.log().info("route found ({}): {:.1f} m over {} nodes, {} cuboids", why, result.cost,
                     result.waypoints.size(), request.obstacles.size());
  node_.publish(channels::kGlobalPath, path_message(result, now, geometric ? &*geometric : nullptr,
                                                    backtrack ? &*backtrack : nullptr));
  node_.set_state(to_string(result.status));
  last_plan_ = std::move(result);
}

}  // namespace ofn::planning
