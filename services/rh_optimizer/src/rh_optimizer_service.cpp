#include "ofn/rh_optimizer/rh_optimizer_service.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "ofn/common/channels.hpp"
#include "ofn/common/message_checks.hpp"
#include "ofn/common/message_names.hpp"
#include "ofn/common/mission_plan.hpp"
#include "ofn/common/ref_traj_sample.hpp"
#include "ofn/common/validate/control_status.hpp"
#include "ofn/common/validate/global_path.hpp"
#include "ofn/common/validate/mission.hpp"
#include "ofn/common/validate/nav_state.hpp"
#include "ofn/common/validate/obstacle_grid.hpp"
#include "ofn/common/validate/scan_world.hpp"

namespace ofn::rh {
namespace {

Vec3 vec3_in(YamlReader& r, const std::string& key, const Vec3& fallback, double lo, double hi) {
  const std::vector<double> v =
      r.numbers_in(key, {fallback.x(), fallback.y(), fallback.z()}, lo, hi);
  return Vec3(v[0], v[1], v[2]);
}

int8_t stats_code(StatsStatus status) {
  switch (status) {
    case StatsStatus::kSolved:
      return solver_stats_t::SOLVED;
    case StatsStatus::kKeptPrevious:
      return solver_stats_t::KEPT_PREVIOUS;
    case StatsStatus::kBraking:
      return solver_stats_t::BRAKING;
    case StatsStatus::kDeferred:
      return solver_stats_t::DEFERRED;
    case StatsStatus::kLookingAround:
      return solver_stats_t::LOOKING_AROUND;
    case StatsStatus::kNoRoute:
      return solver_stats_t::NO_ROUTE;
    case StatsStatus::kNotRun:
      break;
  }
  return solver_stats_t::NOT_RUN;
}

int8_t traj_mode(PlanMode mode) {
  switch (mode) {
    case PlanMode::kAvoidance:
      return ref_traj_t::AVOIDANCE;
    case PlanMode::kPrevious:
      return ref_traj_t::PREVIOUS;
    case PlanMode::kLookAround:
      return ref_traj_t::LOOK_AROUND;
    case PlanMode::kLookAroundLeft:
      return ref_traj_t::LOOK_AROUND_LEFT;
    case PlanMode::kBraking:
      break;
  }
  return ref_traj_t::BRAKING;
}

SupervisorSettings supervisor_settings(const RhOptimizerServiceConfig& c) {
  SupervisorSettings s;
  s.rate = c.rate;
  s.nav_max_age = c.nav_max_age;
  s.grid_max_age = c.grid_max_age;
  s.path_max_age = c.path_max_age;
  s.route_change_distance = c.route_change_distance;
  s.defer_margin = c.defer_margin;
  s.start.planned_initial_state = c.planned_initial_state;
  s.start.replan_position_error = c.replan_position_error;
  s.start.replan_velocity_error = c.replan_velocity_error;
  s.start.planned_initial_acceleration = c.planned_initial_acceleration;
  s.start.stop_recapture_error = c.stop_recapture_error;
  s.optimizer = c.optimizer;
  s.fallback = c.fallback;
  s.commit = c.commit;
  s.avoidance = c.avoidance;
  s.recovery = c.recovery;
  s.passages = c.passages;
  s.scan_supply = c.scan_supply;
  s.tracking_tube = c.tracking_tube;
  return s;
}

}  // namespace

RhOptimizerServiceConfig load_rh_optimizer_config(YamlReader& r) {
  RhOptimizerServiceConfig c;
  c.rate = r.number_in("rate_hz", c.rate, 0.5, 100.0);
  c.nav_max_age = r.number_in("nav_max_age", c.nav_max_age, 0.01, 10.0);
  c.grid_max_age = r.number_in("grid_max_age", c.grid_max_age, 0.05, 60.0);
  c.path_max_age = r.number_in("path_max_age", c.path_max_age, 0.1, 600.0);
  c.sample_period = r.number_in("sample_period", c.sample_period, 0.0, 1.0);
  if (c.sample_period > 0 && c.sample_period < 0.01)
    r.fail("sample_period", "expected 0 (the spline alone) or 0.01 to 1 s");
  c.route_change_distance =
      r.number_in("route_change_distance", c.route_change_distance, 0.1, 1000.0);
  c.field_period = r.number_in("field_period", c.field_period, 0.0, 10.0);
  c.field_altitude_band = r.number_in("field_altitude_band", c.field_altitude_band, 5.0, 1000.0);
  c.occlusion_depth = r.number_in("occlusion_depth", c.occlusion_depth, 0.0, 500.0);
  c.visibility_band = r.number_in("visibility_band", c.visibility_band, 0.1, 100.0);
  c.unseen_extension = r.number_in("unseen_extension", c.unseen_extension, 0.0, 50.0);
  c.unseen_near_reach = r.number_in("unseen_near_reach", c.unseen_near_reach, 0.0, 100.0);
  c.unseen_near_exempt = r.number_in("unseen_near_exempt", c.unseen_near_exempt, 0.0, 100.0);
  if (c.unseen_near_reach > 0 && !(c.unseen_near_exempt < c.unseen_near_reach))
    r.fail("unseen_near_exempt", "expected less than unseen_near_reach (or unseen_near_reach 0)");
  c.planned_initial_acceleration =
      r.boolean("planned_initial_acceleration", c.planned_initial_acceleration);
  c.planned_initial_state = r.boolean("planned_initial_state", c.planned_initial_state);
  c.replan_position_error =
      r.number_in("replan_position_error", c.replan_position_error, 0.0, 1000.0);
  c.replan_velocity_error =
      r.number_in("replan_velocity_error", c.replan_velocity_error, 0.0, 100.0);
  c.stop_recapture_error = r.number_in("stop_recapture_error", c.stop_recapture_error, 0.0, 1000.0);
  c.defer_margin = r.number_in("defer_margin", c.defer_margin, 0.0, 1000.0);

  YamlReader field = r.child("distance_field");
  c.field.vertical_resolution =
      field.number_in("vertical_resolution", c.field.vertical_resolution, 0.1, 10.0);
  c.field.max_distance = field.number_in("max_distance", c.field.max_distance, 5.0, 500.0);
  field.finish();

  YamlReader o = r.child("optimizer");
  RhSettings& s = c.optimizer;
  s.degree = o.integer("degree", s.degree);
  s.intervals = o.integer("intervals", s.intervals);
  s.collocation_points = o.integer("collocation_points", s.collocation_points);
  s.time_constants = vec3_in(o, "time_constants", s.time_constants, 0.01, 10.0);
  s.weights = vec3_in(o, "weights", s.weights, 1e-3, 1e6);
  s.time_weight = o.number_in("time_weight", s.time_weight, 0.0, 1e6);
  s.zero_terminal_accel = o.boolean("zero_terminal_accel", s.zero_terminal_accel);
  s.speed_margin = o.number_in("speed_margin", s.speed_margin, 0.0, 0.5);
  s.accel_margin = o.number_in("accel_margin", s.accel_margin, 0.0, 0.5);
  s.forward_speed_reserve = o.number_in("forward_speed_reserve", s.forward_speed_reserve, 0.0, 1.0);
  s.clearance_margin = o.number_in("clearance_margin", s.clearance_margin, 0.0, 100.0);
  s.min_altitude = o.number_in("min_altitude", s.min_altitude, 0.0, 1e4);
  s.ground_altitude = o.number_in("ground_altitude", s.ground_altitude, -1e4, 1e4);
  s.min_duration = o.number_in("min_duration", s.min_duration, 0.1, 1000.0);
  s.max_duration = o.number_in("max_duration", s.max_duration, 0.2, 1000.0);
  if (s.max_duration <= s.min_duration) o.fail("max_duration", "must exceed min_duration");
  s.max_iterations = o.integer("max_iterations", s.max_iterations);
  s.max_solve_time = o.number_in("max_solve_time", s.max_solve_time, 0.001, 10.0);
  s.feasibility_tolerance =
      o.number_in("feasibility_tolerance", s.feasibility_tolerance, 1e-8, 0.5);
  s.screening_margin = o.number_in("screening_margin", s.screening_margin, 0.0, 100.0);
  s.max_screening_rounds = o.integer("max_screening_rounds", s.max_screening_rounds);
  if (s.max_screening_rounds < 1) o.fail("max_screening_rounds", "must be >= 1");
  const std::string algorithm =
      o.text("algorithm", s.algorithm == RhAlgorithm::kMma ? "mma" : "slsqp");
  if (algorithm == "slsqp")
    s.algorithm = RhAlgorithm::kSlsqp;
  else if (algorithm == "mma")
    s.algorithm = RhAlgorithm::kMma;
  else
    o.fail("algorithm", "expected slsqp or mma");
  o.finish();

  YamlReader f = r.child("fallback");
  FallbackSettings& b = c.fallback;
  b.start_inside_fraction = f.number_in("start_inside_fraction", b.start_inside_fraction, 0.0, 1.0);
  b.keep_min_remaining = f.number_in("keep_min_remaining", b.keep_min_remaining, 0.0, 60.0);
  b.braking_accel_fraction =
      f.number_in("braking_accel_fraction", b.braking_accel_fraction, 0.05, 1.0);
  b.cold_retry = f.boolean("cold_retry", b.cold_retry);
  b.stall_retry = f.boolean("stall_retry", b.stall_retry);
  b.short_retry = f.boolean("short_retry", b.short_retry);
  b.short_retry_fraction = f.number_in("short_retry_fraction", b.short_retry_fraction, 0.05, 0.95);
  b.hover_retry = f.boolean("hover_retry", b.hover_retry);
  b.hover_retry_speed = f.number_in("hover_retry_speed", b.hover_retry_speed, 0.0, 5.0);
  b.braking_retry_period = f.number_in("braking_retry_period", b.braking_retry_period, 0.0, 10.0);
  b.climb_fraction = f.number_in("climb_fraction", b.climb_fraction, 0.1, 1.0);
  f.finish();

  // The stop's deceleration is fallback.braking_accel_fraction and its
  // ground rule the optimiser's: RhPlanner passes them to the gate.
  {
    YamlReader v = r.child("recovery");
    RecoverySettings& d = c.recovery;
    d.enabled = v.boolean("enabled", d.enabled);
    d.stuck_time = v.number_in("stuck_time", d.stuck_time, 0.5, 60.0);
    d.hover_speed = v.number_in("hover_speed", d.hover_speed, 0.01, 5.0);
    d.progress_time = v.number_in("progress_time", d.progress_time, 1.0, 600.0);
    d.progress_radius = v.number_in("progress_radius", d.progress_radius, 0.1, 100.0);
    d.look_timeout = v.number_in("look_timeout", d.look_timeout, 1.0, 300.0);
    d.route_wait = v.number_in("route_wait", d.route_wait, 0.0, 60.0);
    d.route_timeout = v.number_in("route_timeout", d.route_timeout, 0.0, 300.0);
    if (d.route_timeout < d.route_wait) v.fail("route_timeout", "must be >= route_wait");
    d.capture_radius = v.number_in("capture_radius", d.capture_radius, 0.1, 100.0);
    d.face_tolerance = v.number_in("face_tolerance", d.face_tolerance, 0.01, 3.14);
    d.face_hold = v.number_in("face_hold", d.face_hold, 0.0, 30.0);
    d.max_attempts = static_cast<int>(v.integer("max_attempts", d.max_attempts));
    if (d.max_attempts < 1 || d.max_attempts > 100) v.fail("max_attempts", "expected 1..100");
    d.climb_step = v.number_in("climb_step", d.climb_step, 0.0, 500.0);
    d.climb_ceiling = v.number_in("climb_ceiling", d.climb_ceiling, 0.0, 1e4);
    d.climb_tolerance = v.number_in("climb_tolerance", d.climb_tolerance, 0.05, 10.0);
    d.climb_extra_time = v.number_in("climb_extra_time", d.climb_extra_time, 0.0, 600.0);
    d.climb_through = v.boolean("climb_through", d.climb_through);
    d.skip_turn_when_seen = v.boolean("skip_turn_when_seen", d.skip_turn_when_seen);
    v.finish();
  }
  {
    YamlReader v = r.child("passages");
    PassageSettings& d = c.passages;
    d.enabled = v.boolean("enabled", d.enabled);
    d.look_distance = v.number_in("look_distance", d.look_distance, 1.0, 1e4);
    d.max_shift = v.number_in("max_shift", d.max_shift, 0.1, 50.0);
    d.max_extent = v.number_in("max_extent", d.max_extent, 0.0, 500.0);
    d.extent_step = v.number_in("extent_step", d.extent_step, 0.1, 50.0);
    d.max_passages = static_cast<int>(v.integer("max_passages", d.max_passages));
    if (d.max_passages < 1 || d.max_passages > MessageLimits::kMaxPassages)
      v.fail("max_passages", "expected 1.." + std::to_string(MessageLimits::kMaxPassages));
    v.finish();
  }
  YamlReader g = r.child("commit");
  CommitSettings& k = c.commit;
  k.commit_time = g.number_in("commit_time", k.commit_time, 0.0, 10.0);
  k.stop_clearance_fraction =
      g.number_in("stop_clearance_fraction", k.stop_clearance_fraction, 0.0, 2.0);
  k.unseen_clearance_fraction =
      g.number_in("unseen_clearance_fraction", k.unseen_clearance_fraction, 0.0, 2.0);
  k.position_tolerance = g.number_in("position_tolerance", k.position_tolerance, 1e-4, 10.0);
  k.velocity_tolerance = g.number_in("velocity_tolerance", k.velocity_tolerance, 1e-4, 10.0);
  k.acceleration_tolerance =
      g.number_in("acceleration_tolerance", k.acceleration_tolerance, 1e-4, 10.0);
  k.limit_tolerance = g.number_in("limit_tolerance", k.limit_tolerance, 0.0, 0.5);
  g.finish();

  YamlReader a = r.child("avoidance");
  SwitchSettings& w = c.avoidance;
  w.engage_margin = a.number_in("engage_margin", w.engage_margin, 0.0, 100.0);
  w.check_spacing = a.number_in("check_spacing", w.check_spacing, 0.1, 10.0);
  w.handback_distance = a.number_in("handback_distance", w.handback_distance, 0.0, 100.0);
  w.handback_hold = a.number_in("handback_hold", w.handback_hold, 0.0, 60.0);
  w.handback_stop_speed = a.number_in("handback_stop_speed", w.handback_stop_speed, 0.0, 100.0);
  a.finish();
  YamlReader sc = r.child("scan_supply");
  ScanSupplySettings& u = c.scan_supply;
  u.enabled = sc.boolean("enabled", u.enabled);
  u.window = sc.number_in("window", u.window, 0.5, 60.0);
  u.starved_below = sc.number_in("starved_below", u.starved_below, 0.0, 1.0);
  u.fed_above = sc.number_in("fed_above", u.fed_above, u.starved_below, 1.0);
  u.max_silence = sc.number_in("max_silence", u.max_silence, 0.1, 60.0);
  u.min_expected = sc.integer("min_expected", u.min_expected);
  if (u.min_expected < 1 || u.min_expected > 10000) sc.fail("min_expected", "expected 1..10000");
  sc.finish();
  YamlReader tt = r.child("tracking_tube");
  TrackingTubeSettings& tube = c.tracking_tube;
  tube.enabled = tt.boolean("enabled", tube.enabled);
  tube.window = tt.number_in("window", tube.window, 0.5, 120.0);
  tube.onset = tt.number_in("onset", tube.onset, 0.0, 100.0);
  tube.max_extra = tt.number_in("max_extra", tube.max_extra, 0.0, 100.0);
  tt.finish();
  r.finish();
  return c;
}

mapping::Heightfield padded_heightfield(const obstacle_grid_t& grid, double pad_distance) {
  const int pad = static_cast<int>(std::ceil(pad_distance / grid.resolution)) + 1;
  mapping::Heightfield f;
  f.resolution = grid.resolution;
  f.rows = grid.rows + 2 * pad;
  f.cols = grid.cols + 2 * pad;
  f.origin_north = grid.origin[0] - pad * grid.resolution;
  f.origin_east = grid.origin[1] - pad * grid.resolution;
  f.top.assign(static_cast<size_t>(f.rows) * f.cols, 0.0f);
  for (int r = 0; r < grid.rows; ++r)
    for (int c = 0; c < grid.cols; ++c)
      f.at(r + pad, c + pad) = grid.top_altitude[static_cast<size_t>(r) * grid.cols + c];
  return f;
}

ref_traj_t trajectory_message(const BsplineTrajectory& trajectory, Utime t0, int8_t mode,
                              double period, Utime utime) {
  ref_traj_t m;
  m.utime = utime;
  m.t0_utime = t0;
  m.frame = "NED";
  m.mode = mode;
  m.degree = trajectory.degree();
  m.knots = trajectory.knot_times();
  m.num_knots = static_cast<int32_t>(m.knots.size());
  for (const auto& p : trajectory.control_points())
    m.control_points.push_back({p.x(), p.y(), p.z()});
  m.num_control_points = static_cast<int32_t>(m.control_points.size());
  // Without samples the plan is one datagram; receivers sample the spline.
  if (period > 0) set_ref_traj_samples(m, trajectory, period);
  m.num_samples = static_cast<int32_t>(m.sample_time.size());
  return m;
}

RhOptimizerService::RhOptimizerService(lcm::LCM& lcm, const Clock& clock,
                                       RhOptimizerServiceConfig config)
    : node_("rh_optimizer", lcm, clock),
      config_(std::move(config)),
      supervisor_(supervisor_settings(config_)),
      visibility_(1.0, config_.visibility_band),
      field_(config_.field) {
  node_.subscribe<nav_state_t>(
      channels::kNavState, [this](const nav_state_t& m) { on_nav(m); },
      SubscribeOptions{config_.nav_max_age, 0.5});
  // A plan is not state: it stays valid however old its stamp is.
  node_.subscribe<mission_t>(
      channels::kMission, [this](const mission_t& m) { on_mission(m); },
      SubscribeOptions{0.0, 0.0});
  node_.subscribe<obstacle_grid_t>(
      channels::kObstacleGrid, [this](const obstacle_grid_t& m) { on_grid(m); },
      SubscribeOptions{config_.grid_max_age, 0.5});
  node_.subscribe<global_path_t>(
      channels::kGlobalPath, [this](const global_path_t& m) { on_global_path(m); },
      SubscribeOptions{config_.path_max_age, 0.5});
  // The controller's leg moves this one on (LegTracker::follow).
  node_.subscribe<control_status_t>(
      channels::kControlStatus, [this](const control_status_t& m) { on_control_status(m); },
      SubscribeOptions{config_.nav_max_age, 0.5});
  if (config_.occlusion_depth > 0)
    node_.subscribe<scan_world_t>(
        channels::kScanWorld, [this](const scan_world_t& m) { on_scan(m); },
        SubscribeOptions{config_.grid_max_age, 0.5});
  node_.add_timer(
      1.0 / config_.rate, [this] { tick(); }, "rh_step");
  node_.add_timer(
      1.0, [this] { publish_passages(node_.now()); }, "narrow_passages");
  node_.set_state("waiting for mission, nav and grid");
}

void RhOptimizerService::on_mission(const mission_t& m) {
  if (mission_ && same_plan(*mission_, m)) return;
  if (m.waypoints.empty()) {
    node_.reject(channels::kMission, "no waypoints");
    return;
  }
  mission_ = m;
  supervisor_.start_mission(m.mission_id, waypoints_from(m), limits_from(m.limits));
  visibility_.clear();
  // As far as the record is kept round the vehicle (on_scan).
  visibility_.set_max_reach(2.0 * m.limits.sensor_range);
  shadows_.clear();
  node_.log().info("mission {} '{}': clearance {:.2f} m (+{:.2f} m planned), accel {:.3f} m/s^2",
                   m.mission_id, printable(m.name), m.limits.clearance,
                   config_.optimizer.clearance_margin, m.limits.max_accel);
}

void RhOptimizerService::on_grid(const obstacle_grid_t& m) {
  if (grid_ && m.utime <= grid_->utime) {
    node_.reject(channels::kObstacleGrid, "grid not newer than the last one");
    return;
  }
  grid_ = m;
  grid_dirty_ = true;
}

void RhOptimizerService::on_global_path(const global_path_t& m) {
  // A route along the leg (also one only too sharp to fly: NO_PATH with
  // points), one that turns back, or none.
  RouteInput route;
  route.utime = m.utime;
  if (m.status == global_path_t::OK || (m.status == global_path_t::NO_PATH && m.points.size() >= 2))
    route.kind = RouteKind::kForward;
  else if (m.status == global_path_t::BACKTRACK && m.points.size() >= 2)
    route.kind = RouteKind::kBacktrack;
  else
    route.kind = RouteKind::kNoPath;
  route.points.reserve(m.points.size());
  for (const auto& p : m.points) route.points.emplace_back(p[0], p[1], p[2]);
  // NO_PATH may still carry the shortest collision-free route (too sharp to
  // fly as it is): a good guess of which way round.
  route.guess =
      (m.status == global_path_t::OK || m.status == global_path_t::NO_PATH) && m.points.size() >= 2;
  std::optional<Vec3> vehicle;
  if (nav_) vehicle = to_vec3(nav_->position);
  log_lines(supervisor_.route(route, vehicle));
}

void RhOptimizerService::on_control_status(const control_status_t& m) {
  supervisor_.controller_leg(m.mission_id, m.active_waypoint);
  // Only while a reference is flown: holding before the mission or done
  // after it, the error says nothing of gusts.
  if (m.mode == control_status_t::WAYPOINT || m.mode == control_status_t::TRAJECTORY ||
      m.mode == control_status_t::SAFE_STOP)
    supervisor_.tracking_error(to_seconds(m.utime),
                               Vec3(m.position_error[0], m.position_error[1], m.position_error[2]));
}

void RhOptimizerService::on_scan(const scan_world_t& m) {
  supervisor_.scan_received(to_seconds(node_.now()), m.scan_index);
  const Vec3 origin = to_vec3(m.sensor_origin);
  const double altitude = -origin.z();
  for (const auto& p : m.points)
    visibility_.add_beam(origin, Vec3(p[0], p[1], p[2]), true, altitude);
  for (const auto& p : m.free_ray_ends)
    visibility_.add_beam(origin, Vec3(p[0], p[1], p[2]), false, altitude);
  // About every 10 s of scans: keep twice the sensor's reach around.
  if (++scans_seen_ % 128 == 0) {
    const double keep = 2.0 * (mission_ ? mission_->limits.sensor_range : 100.0);
    visibility_.forget_beyond(origin, keep);
    shadows_.forget_beyond(origin, keep);
  }
}

MapView RhOptimizerService::refresh_field(Utime now, const Vec3& vehicle) {
  MapView map;
  map.heightfield = &heightfield_;
  map.clearance = [this](const Vec3& p) { return field_.query(p); };
  if (config_.occlusion_depth > 0)
    map.seen = [this](double north, double east) { return visibility_.seen(north, east); };
  if (!grid_) return map;
  const double vehicle_altitude = -vehicle.z();
  const bool band_moved =
      std::abs(vehicle_altitude - field_altitude_) > 0.25 * config_.field_altitude_band;
  const bool due = field_built_ == INT64_MIN ||
                   now - field_built_ >= to_utime(config_.field_period) || band_moved;
  if (field_valid_ && !(grid_dirty_ && due) && !band_moved) return map;
  heightfield_ = padded_heightfield(*grid_, config_.field.max_distance + config_.occlusion_depth);
  const double ground = config_.optimizer.ground_altitude;
  const double alt = vehicle_altitude - ground;
  if (config_.occlusion_depth > 0) {
    if (config_.unseen_extension > 0) mapped_ = heightfield_;
    // Cast on the map alone (a shadow casts none of its own), then add
    // the shadows remembered from earlier viewpoints.
    cast_occlusion_shadows(heightfield_, visibility_, vehicle, alt, config_.occlusion_depth, 2.0,
                           &shadows_);
    shadows_.apply(heightfield_, visibility_);
    // What was not seen is as tall as anything the field holds.
    const auto unknown_top = static_cast<float>(alt + config_.field_altitude_band);
    // Beside what was mapped, what was not seen may be more of it. Tops
    // lower than 1 m are the ground (the mapper's ground_clearance), not
    // obstacles to extend.
    if (config_.unseen_extension > 0)
      extend_into_unseen(mapped_, heightfield_, visibility_, vehicle, config_.unseen_extension,
                         1.0f, unknown_top);
    if (config_.unseen_near_reach > 0)
      raise_unseen_near(heightfield_, visibility_, vehicle, config_.unseen_near_exempt,
                        config_.unseen_near_reach, unknown_top);
  }
  const double lo = std::max(0.0, alt - config_.field_altitude_band);
  const double hi = std::max(lo + 1.0, alt + config_.field_altitude_band);
  field_.build(heightfield_, lo, hi);
  field_map_utime_ = grid_->utime;
  field_valid_ = true;
  field_built_ = now;
  field_altitude_ = vehicle_altitude;
  grid_dirty_ = false;
  return map;
}

void RhOptimizerService::publish_nominal(Utime now, const Vec3& position, const Vec3& velocity) {
  // Two samples of where the vehicle is: a NOMINAL trajectory tells the
  // controller to drop the avoidance reference now.
  ref_traj_t m;
  m.utime = now;
  m.t0_utime = now;
  m.frame = "NED";
  m.mode = ref_traj_t::NOMINAL;
  m.degree = 0;
  m.num_knots = 0;
  m.num_control_points = 0;
  const double period = config_.sample_period > 0 ? config_.sample_period : kRefTrajSamplePeriod;
  m.sample_time = {0.0, period};
  const Vec3 ahead = position + velocity * period;
  m.position = {{position.x(), position.y(), position.z()}, {ahead.x(), ahead.y(), ahead.z()}};
  m.velocity = {{velocity.x(), velocity.y(), velocity.z()},
                {velocity.x(), velocity.y(), velocity.z()}};
  m.acceleration = {{0, 0, 0}, {0, 0, 0}};
  m.num_samples = 2;
  node_.publish(channels::kRefTraj, m);
}

narrow_passages_t passages_message(const std::vector<NarrowPassage>& passages, int32_t mission_id,
                                   Utime utime) {
  narrow_passages_t m;
  m.utime = utime;
  m.frame = "NED";
  m.mission_id = mission_id;
  m.num_passages = static_cast<int32_t>(passages.size());
  for (const NarrowPassage& p : passages) {
    m.centre.push_back({p.centre.x(), p.centre.y(), p.centre.z()});
    m.radius.push_back(p.radius);
    m.half_height.push_back(p.half_height);
  }
  return m;
}

void RhOptimizerService::publish_passages(Utime now) {
  if (!mission_ || !config_.passages.enabled) return;
  node_.publish(channels::kNarrowPassages,
                passages_message(supervisor_.passages(), mission_->mission_id, now));
}

void RhOptimizerService::log_lines(const std::vector<LogLine>& lines) {
  for (const LogLine& line : lines) {
    if (line.level == LogLine::Level::kWarn)
      node_.log().warn("{}", line.text);
    else
      node_.log().info("{}", line.text);
  }
}

void RhOptimizerService::publish_stats(Utime now, const SupervisorDecision& d) {
  solver_stats_t s{};
  s.guidance_clear = d.guidance_clear && field_valid_;
  s.mission_id = mission_ ? mission_->mission_id : -1;
  s.active_waypoint = supervisor_.active_leg();
  s.utime = now;
  s.status = stats_code(d.status);
  s.message = d.message;
  if (d.report) {
    const SolveReport& report = *d.report;
    s.iterations = report.iterations;
    s.solve_time = report.solve_time;
    s.max_constraint_violation = std::isfinite(report.max_violation) ? report.max_violation : 1e9;
    s.cost = std::isfinite(report.cost) ? report.cost : 0.0;
    s.warm_started = report.warm_started;
  }
  s.map_utime = field_valid_ ? field_map_utime_ : 0;
  node_.publish(channels::kSolverStats, s);
}

void RhOptimizerService::tick() {
  const Utime now = node_.now();
  TickInput in;
  in.now = now;
  if (nav_) {
    NavInput nav;
    nav.utime = nav_->utime;
    nav.position = to_vec3(nav_->position);
    nav.velocity = to_vec3(nav_->velocity);
    nav.acceleration = to_vec3(nav_->acceleration);
    nav.yaw = nav_->euler[2];
    in.nav = nav;
  }
  if (grid_) in.grid_utime = grid_->utime;
  in.map = [this, now, &in] { return refresh_field(now, in.nav->position); };
  const SupervisorDecision d = supervisor_.tick(in);

  if (d.state != last_note_) node_.set_state(d.state);
  last_note_ = d.state;
  // In the order the decisions were taken: the narrow passage found on the
  // way, the trajectory, the step's report.
  if (d.passages_changed) publish_passages(now);
  using Publish = SupervisorDecision::Publish;
  switch (d.publish) {
    case Publish::kNothing:
    case Publish::kStats:
      break;
    case Publish::kNominal:
      publish_nominal(now, in.nav->position, in.nav->velocity);
      break;
    case Publish::kHover:
    case Publish::kStep:
      node_.publish(channels::kRefTraj, trajectory_message(d.trajectory, d.t0, traj_mode(d.mode),
                                                           config_.sample_period, now));
      break;
  }
  log_lines(d.log);
  if (d.publish == Publish::kNothing) return;
  // One line per streak of like failed steps (the first in full, then a
  // summary); every step's message still goes out in SOLVER_STATS.
  const double t = to_seconds(now);
  const std::vector<std::string> streak =
      d.warning ? warning_streak_.warn(t, d.warning->kind, d.warning->text, d.warning->figure)
                : warning_streak_.clear(t);
  for (const std::string& line : streak) node_.log().warn("{}", line);
  publish_stats(now, d);
}

}  // namespace ofn::rh
