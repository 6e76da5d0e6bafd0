#include "ofn/viewer/view_state.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "ofn/common/braking.hpp"
#include "ofn/common/channels.hpp"
#include "ofn/common/message_names.hpp"
#include "ofn/common/node.hpp"
#include "ofn/common/obstacle_messages.hpp"
#include "ofn/common/ref_traj_sample.hpp"
#include "ofn/common/validate.hpp"

namespace ofn::viewer {
namespace {

using nlohmann::json;

json vec(const Vec3& v) {
  return json::array({v.x(), v.y(), v.z()});
}
json vec(const double (&a)[3]) {
  return json::array({a[0], a[1], a[2]});
}
json points(const std::vector<std::vector<double>>& rows) {
  json out = json::array();
  for (const auto& r : rows) out.push_back(json::array({r[0], r[1], r[2]}));
  return out;
}

}  // namespace

void check(const ViewStateConfig& c) {
  auto positive = [](double v) { return std::isfinite(v) && v > 0; };
  if (c.trail_max_points < 2) throw std::invalid_argument("trail points must be at least 2");
  if (!(std::isfinite(c.trail_min_spacing) && c.trail_min_spacing >= 0))
    throw std::invalid_argument("trail spacing must be a finite number >= 0");
  if (!positive(c.stale_after)) throw std::invalid_argument("stale-after must be > 0");
  if (!positive(c.timeline_reset_gap))
    throw std::invalid_argument("timeline reset gap must be > 0");
  if (c.max_grid_cells < 1) throw std::invalid_argument("grid cells must be at least 1");
  if (!(std::isfinite(c.ref_traj_timeout) && c.ref_traj_timeout >= 0))
    throw std::invalid_argument("ref-traj-timeout must be a finite number >= 0");
  if (!(positive(c.stop_accel_fraction) && c.stop_accel_fraction <= 1))
    throw std::invalid_argument("stop-accel-fraction must be in (0, 1]");
  if (c.display_unit != "ft" && c.display_unit != "m")
    throw std::invalid_argument("display unit must be ft or m, got '" + c.display_unit + "'");
}

ViewState::ViewState(ViewStateConfig config) : config_(std::move(config)) {
  check(config_);
}

std::string ViewState::reject(const std::string& channel, const std::string& reason) {
  // Counted by kind in a bounded table, as the node does: a flood of
  // distinct reasons must not grow the viewer's memory.
  const std::string key = channel + ": " + reason;
  const std::string kind = reject_kind(key);
  if (counters_.rejected.count(kind) || counters_.rejected.size() < kMaxRejectKinds)
    ++counters_.rejected[kind];
  else
    ++counters_.rejected[kOtherRejectKind];
  ++counters_.rejected_total;
  counters_.last_rejection = key;
  return reason;
}

void ViewState::count_rejection(const std::string& channel, const std::string& reason) {
  reject(channel, reason);
}

template <class Msg>
std::string ViewState::accept(const char* channel, const Msg& msg, Utime stamp, Utime& last_stamp) {
  if (std::string why = validate(msg); !why.empty()) return reject(channel, why);
  if (stamp < 0) return reject(channel, "negative stamp");
  if (last_stamp != INT64_MIN && stamp < last_stamp) return reject(channel, "stamp went backwards");
  last_stamp = stamp;
  ++counters_.accepted[channel];
  return "";
}

void ViewState::start_new_timeline() {
  ++counters_.timeline_resets;
  // Everything stamped on the old timeline belongs to the old flight. The
  // mission and the injected obstacles are kept: a replayed log or a
  // restarted simulation flies the same course, and both are sent again.
  nav_.reset();
  trail_.clear();
  trail_length_ = 0;
  status_.reset();
  ref_traj_.reset();
  solver_.reset();
  path_.reset();
  cuboids_.reset();
  grid_.reset();
  passages_.reset();
  last_nav_ = last_status_ = last_ref_ = last_solver_ = last_path_ = last_cuboids_ = last_grid_ =
      last_mission_ = last_obstacles_ = last_passages_ = INT64_MIN;
}

std::string ViewState::on_nav_state(const nav_state_t& msg) {
  const char* channel = channels::kNavState;
  if (last_nav_ != INT64_MIN && msg.utime < last_nav_ - to_utime(config_.timeline_reset_gap) &&
      validate(msg).empty() && msg.utime >= 0)
    start_new_timeline();
  if (auto why = accept(channel, msg, msg.utime, last_nav_); !why.empty()) return why;
  nav_ = msg;
  const Vec3 p = to_vec3(msg.position);
  if (trail_.empty() || (p - trail_.back().position).norm() >= config_.trail_min_spacing) {
    if (!trail_.empty()) trail_length_ += (p - trail_.back().position).norm();
    trail_.push_back({to_seconds(msg.utime), p});
    while (trail_.size() > config_.trail_max_points) trail_.pop_front();
  }
  return "";
}

std::string ViewState::on_control_status(const control_status_t& msg) {
  if (auto why = accept(channels::kControlStatus, msg, msg.utime, last_status_); !why.empty())
    return why;
  status_ = msg;
  return "";
}

std::string ViewState::on_ref_traj(const ref_traj_t& msg) {
  if (auto why = accept(channels::kRefTraj, msg, msg.utime, last_ref_); !why.empty()) return why;
  ref_traj_ = msg;
  expand_ref_traj(*ref_traj_);  // a plan sent as its spline alone
  return "";
}

std::string ViewState::on_solver_stats(const solver_stats_t& msg) {
  if (auto why = accept(channels::kSolverStats, msg, msg.utime, last_solver_); !why.empty())
    return why;
  solver_ = msg;
  return "";
}

std::string ViewState::on_global_path(const global_path_t& msg) {
  if (auto why = accept(channels::kGlobalPath, msg, msg.utime, last_path_); !why.empty())
    return why;
  path_ = msg;
  return "";
}

std::string ViewState::on_narrow_passages(const narrow_passages_t& msg) {
  if (auto why = accept(channels::kNarrowPassages, msg, msg.utime, last_passages_); !why.empty())
    return why;
  passages_ = msg;
  return "";
}

std::string ViewState::on_cuboids(const cuboid_list_t& msg) {
  if (auto why = accept(channels::kCuboids, msg, msg.utime, last_cuboids_); !why.empty())
    return why;
  cuboids_ = msg;
  return "";
}

std::string ViewState::on_obstacle_grid(const obstacle_grid_t& msg) {
  if (auto why = accept(channels::kObstacleGrid, msg, msg.utime, last_grid_); !why.empty())
    return why;
  grid_ = msg;
  return "";
}

std::string ViewState::on_mission(const mission_t& msg) {
  if (auto why = accept(channels::kMission, msg, msg.utime, last_mission_); !why.empty())
    return why;
  mission_ = msg;
  return "";
}

std::string ViewState::on_virtual_obstacles(const virtual_obstacles_t& msg) {
  if (auto why = accept(channels::kVirtualObstacles, msg, msg.utime, last_obstacles_); !why.empty())
    return why;
  obstacles_ = msg;
  std::vector<ObstacleSpec> specs;
  specs.reserve(msg.obstacles.size());
  for (const auto& o : msg.obstacles) specs.push_back(from_message(o));
  truth_ = world::World(specs, msg.ground_altitude);
  return "";
}

std::optional<double> ViewState::age(Utime stamp) const {
  if (!nav_) return std::nullopt;
  return to_seconds(nav_->utime - stamp);
}

json ViewState::safe_stop_json() const {
  // The stop the controller flies when this plan goes stale: from the
  // plan's state ref_traj_timeout after its stamp, at stop_accel_fraction of
  // the acceleration limit (docs/PLANNING.md, "A safe stop from every
  // committed instant"). Needs the limit from MISSION.
  if (!ref_traj_ || !mission_) return nullptr;
  // Held at the plan's ends, as the controller holds to the last state it
  // flew.
  const auto& ts = ref_traj_->sample_time;
  const double t =
      std::clamp(to_seconds(ref_traj_->utime - ref_traj_->t0_utime) + config_.ref_traj_timeout,
                 ts.front(), ts.back());
  const auto at = sample_ref_traj_at(*ref_traj_, t);
  if (!at) return nullptr;
  const auto stop = stop_from(at->position, at->velocity, at->acceleration,
                              config_.stop_accel_fraction * mission_->limits.max_accel);
  return json{{"start", vec(at->position)},
              {"point", vec(stop.stop_point())},
              {"distance", stop.distance()},
              {"time", stop.stop_time}};
}

std::string ViewState::to_text(const json& snapshot) {
  return snapshot.dump(-1, ' ', false, json::error_handler_t::replace);
}

json ViewState::snapshot() const {
  json s;
  s["display_unit"] = config_.display_unit;
  s["units"] = "SI, world NED (north, east, down), metres, seconds";

  json vehicle = nullptr;
  if (nav_) {
    const Vec3 v = to_vec3(nav_->velocity);
    vehicle = json{{"t", to_seconds(nav_->utime)},
                   {"position", vec(nav_->position)},
                   {"velocity", vec(nav_->velocity)},
                   {"speed", v.norm()},
                   {"horizontal_speed", std::hypot(v.x(), v.y())},
                   {"altitude", -nav_->position[2]},
                   {"yaw", nav_->euler[2]}};
    if (obstacles_) {
      // The true clearance, as the flight report measures it: the nearest
      // injected obstacle surface or the ground.
      const Vec3 p = to_vec3(nav_->position);
      const double to_obstacle = truth_.distance_to_obstacles(p);
      const double to_ground = truth_.distance_to_ground(p);
      vehicle["clearance"] = std::min(to_obstacle, to_ground);
      vehicle["clearance_to"] = to_ground <= to_obstacle ? "ground" : "obstacle";
    } else {
      vehicle["clearance"] = nullptr;
    }
  }
  s["vehicle"] = vehicle;

  json trail = json::array();
  for (const auto& p : trail_) trail.push_back(vec(p.position));
  s["trail"] = trail;
  s["trail_length"] = trail_length_;

  if (status_) {
    s["control"] = json{{"mode", control_mode_name(status_->mode)},
                        {"active_waypoint", status_->active_waypoint},
                        {"ref_position", vec(status_->ref_position)},
                        {"ref_traj_fresh", status_->ref_traj_fresh},
                        {"age", age(status_->utime).value_or(0.0)},
                        {"stale", age(status_->utime).value_or(0.0) > config_.stale_after}};
  } else {
    s["control"] = nullptr;
  }

  if (solver_) {
    s["solver"] = json{{"status", solver_status_name(solver_->status)},
                       {"message", solver_->message},
                       {"iterations", solver_->iterations},
                       {"solve_time", solver_->solve_time},
                       {"max_constraint_violation", solver_->max_constraint_violation},
                       {"cost", solver_->cost},
                       {"age", age(solver_->utime).value_or(0.0)},
                       {"stale", age(solver_->utime).value_or(0.0) > config_.stale_after}};
  } else {
    s["solver"] = nullptr;
  }

  if (ref_traj_) {
    s["ref_traj"] = json{{"mode", ref_traj_mode_name(ref_traj_->mode)},
                         {"positions", points(ref_traj_->position)},
                         {"age", age(ref_traj_->utime).value_or(0.0)},
                         {"stale", age(ref_traj_->utime).value_or(0.0) > config_.stale_after},
                         {"safe_stop", safe_stop_json()}};
  } else {
    s["ref_traj"] = nullptr;
  }

  if (path_) {
    s["global_path"] = json{{"status", path_status_name(path_->status)},
                            {"cost", path_->cost},
                            {"points", points(path_->points)},
                            {"age", age(path_->utime).value_or(0.0)},
                            {"stale", age(path_->utime).value_or(0.0) > config_.stale_after}};
  } else {
    s["global_path"] = nullptr;
  }

  // The passages the RH optimiser found too narrow to fly, which the
  // global planner routes round (of the mission the list names).
  json passages = json::array();
  if (passages_ && (!mission_ || passages_->mission_id == mission_->mission_id))
    for (size_t i = 0; i < passages_->centre.size(); ++i)
      passages.push_back(
          json{{"centre", json::array({passages_->centre[i][0], passages_->centre[i][1],
                                       passages_->centre[i][2]})},
               {"radius", passages_->radius[i]},
               {"half_height", passages_->half_height[i]}});
  s["narrow_passages"] = passages;

  json cuboids = json::array();
  if (cuboids_)
    for (const auto& c : cuboids_->cuboids)
      cuboids.push_back(json{{"id", c.id},
                             {"min", vec(c.min_corner)},
                             {"max", vec(c.max_corner)},
                             {"top_observed", c.top_observed}});
  s["cuboids"] = cuboids;

  if (grid_) {
    // Occupied cells as [north, east, top altitude] of the cell centre,
    // nearest to the vehicle first when there are more than the page takes.
    struct Cell {
      double north, east, top, distance2;
    };
    std::vector<Cell> cells;
    const double vn = nav_ ? nav_->position[0] : 0.0, ve = nav_ ? nav_->position[1] : 0.0;
    for (int r = 0; r < grid_->rows; ++r)
      for (int c = 0; c < grid_->cols; ++c) {
        const float top = grid_->top_altitude[static_cast<size_t>(r) * grid_->cols + c];
        if (!(top > 0)) continue;
        const double n = grid_->origin[0] + (r + 0.5) * grid_->resolution;
        const double e = grid_->origin[1] + (c + 0.5) * grid_->resolution;
        cells.push_back({n, e, top, (n - vn) * (n - vn) + (e - ve) * (e - ve)});
      }
    const size_t total = cells.size();
    if (cells.size() > config_.max_grid_cells) {
      std::nth_element(cells.begin(), cells.begin() + config_.max_grid_cells, cells.end(),
                       [](const Cell& a, const Cell& b) { return a.distance2 < b.distance2; });
      cells.resize(config_.max_grid_cells);
    }
    json out = json::array();
    for (const auto& c : cells) out.push_back(json::array({c.north, c.east, c.top}));
    s["grid"] = json{{"resolution", grid_->resolution},
                     {"cells", out},
                     {"occupied", total},
                     {"left_out", total - cells.size()},
                     {"age", age(grid_->utime).value_or(0.0)}};
  } else {
    s["grid"] = nullptr;
  }

  if (mission_) {
    json waypoints = json::array();
    for (const auto& w : mission_->waypoints) waypoints.push_back(vec(w.position));
    const auto& l = mission_->limits;
    s["mission"] = json{{"name", mission_->name},
                        {"waypoints", waypoints},
                        {"limits",
                         {{"max_speed", l.max_speed},
                          {"max_accel", l.max_accel},
                          {"clearance", l.clearance},
                          {"sensor_range", l.sensor_range}}}};
  } else {
    s["mission"] = nullptr;
  }

  if (obstacles_) {
    json list = json::array();
    for (const auto& o : obstacles_->obstacles)
      list.push_back(json{{"id", o.id},
                          {"kind", o.kind == obstacle_t::BOX        ? "box"
                                   : o.kind == obstacle_t::CYLINDER ? "cylinder"
                                                                    : "tree"},
                          {"center", json::array({o.center[0], o.center[1]})},
                          {"size", json::array({o.size[0], o.size[1]})},
                          {"height", o.height},
                          {"yaw", o.yaw}});
    s["obstacles"] = json{{"ground_altitude", obstacles_->ground_altitude}, {"list", list}};
  } else {
    s["obstacles"] = nullptr;
  }

  s["counters"] = json{{"accepted", counters_.accepted},
                       {"rejected", counters_.rejected},
                       {"rejected_total", counters_.rejected_total},
                       {"timeline_resets", counters_.timeline_resets},
                       {"last_rejection", counters_.last_rejection}};
  return s;
}

}  // namespace ofn::viewer
