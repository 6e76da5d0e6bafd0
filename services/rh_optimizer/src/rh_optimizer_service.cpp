#include "ofn/rh_optimizer/rh_optimizer_service.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <fmt/format.h>

#include "ofn/common/channels.hpp"
#include "ofn/common/message_checks.hpp"
#include "ofn/common/ref_traj_sample.hpp"
#include "ofn/common/validate/control_status.hpp"
#include "ofn/common/validate/global_path.hpp"
#include "ofn/common/validate/mission.hpp"
#include "ofn/common/validate/nav_state.hpp"
#include "ofn/common/validate/obstacle_grid.hpp"
#include "ofn/common/validate/scan_world.hpp"
#include "ofn/rh_optimizer/start_state.hpp"
#include "ofn/rh_optimizer/step_problem.hpp"

namespace ofn::rh {
namespace {

Vec3 vec3_in(YamlReader& r, const std::string& key, const Vec3& fallback, double lo, double hi) {
  const std::vector<double> v =
      r.numbers_in(key, {fallback.x(), fallback.y(), fallback.z()}, lo, hi);
  return Vec3(v[0], v[1], v[2]);
}

int8_t stats_status(StepMode mode) {
  switch (mode) {
    case StepMode::kSolved:
      return solver_stats_t::SOLVED;
    case StepMode::kKeptPrevious:
      return solver_stats_t::KEPT_PREVIOUS;
    case StepMode::kBraking:
      break;
  }
  return solver_stats_t::BRAKING;
}

int8_t traj_mode(StepMode mode) {
  switch (mode) {
    case StepMode::kSolved:
      return ref_traj_t::AVOIDANCE;
    case StepMode::kKeptPrevious:
      return ref_traj_t::PREVIOUS;
    case StepMode::kBraking:
      break;
  }
  return ref_traj_t::BRAKING;
}

double distance_to_polyline(const std::vector<Vec3>& line, const Vec3& p) {
  double best = std::numeric_limits<double>::infinity();
  if (line.size() == 1) return (line[0] - p).norm();
  for (size_t i = 1; i < line.size(); ++i)
    best = std::min(best, distance_to_segment(p, line[i - 1], line[i]));
  return best;
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

double route_difference(const std::vector<Vec3>& a, const std::vector<Vec3>& b, const Vec3& from,
                        double horizon) {
  if (a.empty() || b.empty()) return std::numeric_limits<double>::infinity();
  double worst = 0;
  for (const auto& p : b) {
    if ((p - from).norm() > horizon) continue;
    worst = std::max(worst, distance_to_polyline(a, p));
  }
  return worst;
}

RhOptimizerService::RhOptimizerService(lcm::LCM& lcm, const Clock& clock,
                                       RhOptimizerServiceConfig config)
    : node_("rh_optimizer", lcm, clock),
      config_(std::move(config)),
      planner_(config_.optimizer, config_.fallback, config_.commit),
      switch_(config_.avoidance),
      visibility_(1.0, config_.visibility_band),
      scan_supply_(config_.scan_supply),
      tube_(config_.tracking_tube),
      field_(config_.field),
      recovery_(config_.recovery),
      passages_(config_.passages.max_passages) {
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
  legs_.clear();
  active_leg_ = -1;
  restart_planning();
  switch_.reset();
  visibility_.clear();
  shadows_.clear();
  passages_.clear();
  node_.log().info("mission {} '{}': clearance {:.2f} m (+{:.2f} m planned), accel {:.3f} m/s^2",
                   m.mission_id, m.name, m.limits.clearance, config_.optimizer.clearance_margin,
                   m.limits.max_accel);
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
  // What the planner says decides a dead end's recovery: a route along the
  // leg (also one only too sharp to fly: NO_PATH with points), one that
  // turns back, or none.
  route_kind_utime_ = m.utime;
  if (m.status == global_path_t::OK || (m.status == global_path_t::NO_PATH && m.points.size() >= 2))
    route_kind_ = RouteKind::kForward;
  else if (m.status == global_path_t::BACKTRACK && m.points.size() >= 2)
    route_kind_ = RouteKind::kBacktrack;
  else
    route_kind_ = RouteKind::kNoPath;
  recovery_route_.clear();
  if (route_kind_ != RouteKind::kNoPath)
    for (const auto& p : m.points) recovery_route_.emplace_back(p[0], p[1], p[2]);
  // NO_PATH may still carry the shortest collision-free route (too sharp to
  // fly as it is): a good guess of which way round.
  if ((m.status != global_path_t::OK && m.status != global_path_t::NO_PATH) || m.points.size() < 2)
    return;
  std::vector<Vec3> points;
  points.reserve(m.points.size());
  for (const auto& p : m.points) points.emplace_back(p[0], p[1], p[2]);
  const Vec3 from = nav_ ? to_vec3(nav_->position) : points.front();
  const double horizon = mission_ ? mission_->limits.sensor_range : 60.0;
  // The planner re-publishes every second; only a different way round is a
  // new route (and a reason to drop the warm start).
  if (route_.empty() ||
      route_difference(route_, points, from, horizon) > config_.route_change_distance) {
    route_changed_ = true;
    if (!route_.empty()) node_.log().info("new global route ({} points)", points.size());
  }
  route_ = std::move(points);
  route_utime_ = m.utime;
}

void RhOptimizerService::on_control_status(const control_status_t& m) {
  legs_.follow(m.mission_id, m.active_waypoint);
  // Only while a reference is flown: holding before the mission or done
  // after it, the error says nothing of gusts.
  if (m.mode == control_status_t::WAYPOINT || m.mode == control_status_t::TRAJECTORY ||
      m.mode == control_status_t::SAFE_STOP)
    tube_.add(to_seconds(m.utime),
              Vec3(m.position_error[0], m.position_error[1], m.position_error[2]));
}

double RhOptimizerService::tracking_widening(Utime now) {
  const double widening = tube_.extra_clearance();
  if (std::abs(widening - logged_widening_) >= 0.25 ||
      (widening == 0.0) != (logged_widening_ == 0.0)) {
    node_.log().info(
        "t={:.2f} s tracking tube: clearances widened by {:.2f} m (largest position error {:.2f} m "
        "over the last {:.0f} s)",
        to_seconds(now), widening, tube_.largest_error(), config_.tracking_tube.window);
    logged_widening_ = widening;
  }
  return widening;
}

void RhOptimizerService::on_scan(const scan_world_t& m) {
  scan_supply_.received(to_seconds(node_.now()), m.scan_index);
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

bool RhOptimizerService::refresh_field(Utime now, const Vec3& vehicle) {
  if (!grid_) return false;
  const double vehicle_altitude = -vehicle.z();
  const bool band_moved =
      std::abs(vehicle_altitude - field_altitude_) > 0.25 * config_.field_altitude_band;
  const bool due = field_built_ == INT64_MIN ||
                   now - field_built_ >= to_utime(config_.field_period) || band_moved;
  if (field_valid_ && !(grid_dirty_ && due) && !band_moved) return true;
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
    // Beside what was mapped, what was not seen may be more of it, as tall
    // as anything the field holds. Tops lower than 1 m are the ground (the
    // mapper's ground_clearance), not obstacles to extend.
    if (config_.unseen_extension > 0) {
      const auto unknown_top = static_cast<float>(alt + config_.field_altitude_band);
      extend_into_unseen(mapped_, heightfield_, visibility_, vehicle, config_.unseen_extension,
                         1.0f, unknown_top);
    }
  }
  const double lo = std::max(0.0, alt - config_.field_altitude_band);
  const double hi = std::max(lo + 1.0, alt + config_.field_altitude_band);
  field_.build(heightfield_, lo, hi);
  field_map_utime_ = grid_->utime;
  field_valid_ = true;
  field_built_ = now;
  field_altitude_ = vehicle_altitude;
  grid_dirty_ = false;
  return true;
}

void RhOptimizerService::hand_back(Utime now, const Vec3& position, const Vec3& velocity,
                                   const std::string& why) {
  publish_nominal(now, position, velocity);
  restart_planning();
  node_.log().info("avoidance hands back to waypoint guidance at t={:.2f} s ({})", to_seconds(now),
                   why);
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

void RhOptimizerService::restart_planning() {
  planner_.reset();
  recovery_.reset();
  last_step_moving_ = false;
  last_trajectory_ = BsplineTrajectory();
  last_trajectory_kind_ = LastPlan::kMoving;
  stopping_at_target_ = false;
  stalled_ = false;
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
                passages_message(passages_.passages(), mission_->mission_id, now));
}

double RhOptimizerService::pinch_clearance(const Limits& limits) const {
  // What the optimiser accepts as feasible: its clearance, less its
  // (normalised) feasibility tolerance. Dense seed 83 blocked a gap 1 cm
  // short of the clearance, which it had flown before, and lost its way.
  return (limits.clearance + config_.optimizer.clearance_margin) *
         (1.0 - config_.optimizer.feasibility_tolerance);
}

bool RhOptimizerService::check_route_for_pinch(Utime now, const Limits& limits,
                                               const GuidanceFrame& leg) {
  if (!field_valid_) return false;
  // On the field the plans are made on, after the look: the shadows
  // behind what was seen (occlusion) it cleared are gone, those left are
  // what the optimiser will meet. (Checked when the vehicle got stuck,
  // before the look, a gap they closed then was open after it: dense seed
  // 68 lost its way so.)
  const ClearanceQuery clearance = [this](const Vec3& p) { return field_.query(p); };
  const double required = pinch_clearance(limits);
  std::optional<NarrowPassage> pinch =
      find_narrow_passage(clearance, recovery_route_, required, config_.passages);
  const char* what = "the route passes a pinch";
  if (!pinch && !recovery_route_.empty()) {
    // An escape flies to the route's first corner and stops there; the
    // route's sections may leave room to pass a corner in a gap but none
    // to stop in it, and the escape stalled there look after look (dense
    // seed 162).
    const auto corner = escape_leg_end(recovery_route_, leg, config_.recovery.capture_radius);
    if (corner && *corner > 0) {
      pinch = find_cramped_stop(clearance, recovery_route_[*corner], required, config_.passages);
      what = "the escape would stop at a corner with no room";
    }
  }
  // One the planner knows already is not its doing (a zone round the
  // start, which routes may leave): the route is taken.
  if (!pinch || !passages_.add(*pinch)) return false;
  const double ground = config_.optimizer.ground_altitude;
  node_.log().warn(
      "t={:.2f} s {} with {:.2f} m of the {:.2f} m clearance: told to the global planner (no "
      "route within {:.1f} m of ({:.1f}, {:.1f}) m north/east, {:.1f} to {:.1f} m above the "
      "ground)",
      to_seconds(now), what, pinch->clearance, required, pinch->radius, pinch->centre.x(),
      pinch->centre.y(), -(pinch->centre.z() + pinch->half_height) - ground,
      -(pinch->centre.z() - pinch->half_height) - ground);
  publish_passages(now);
  return true;
}

RecoveryDecision RhOptimizerService::update_recovery(Utime now, const Leg& leg,
                                                     const Limits& limits, const Vec3& position,
                                                     const Vec3& velocity, bool engaged) {
  RecoveryInput in;
  in.time = to_seconds(now);
  in.position = position;
  in.velocity = velocity;
  in.altitude = -position.z() - config_.optimizer.ground_altitude;
  in.max_vertical_speed = limits.max_vertical_speed;
  in.yaw = nav_->euler[2];
  in.engaged = engaged;
  in.moving_plan = last_step_moving_;
  in.route = route_kind_;
  in.route_time = route_kind_utime_ == INT64_MIN ? -1e300 : to_seconds(route_kind_utime_);
  in.route_points = &recovery_route_;
  in.leg = GuidanceFrame::from_leg(leg.from, leg.to);
  in.route_flyable = [&] { return !check_route_for_pinch(now, limits, in.leg); };
  RecoveryDecision decision = recovery_.update(in);
  if (decision.changed) {
    node_.log().warn("t={:.2f} s recovery: {}: {}", in.time, to_string(decision.phase),
                     decision.reason);
    // Each phase plans afresh: an escape in its own frame, normal planning
    // from wherever the escape or the look left the vehicle.
    planner_.reset();
    route_changed_ = true;
    last_step_moving_ = false;
  }
  return decision;
}

void RhOptimizerService::publish_stats(Utime now, int8_t status, const std::string& message,
                                       const SolveReport* report, bool guidance_clear) {
  if (!step_warned_)
    for (const std::string& line : warning_streak_.clear(to_seconds(now)))
      node_.log().warn("{}", line);
  step_warned_ = false;
  solver_stats_t s{};
  s.guidance_clear = guidance_clear && field_valid_;
  s.mission_id = mission_ ? mission_->mission_id : -1;
  s.active_waypoint = active_leg_;
  s.utime = now;
  s.status = status;
  s.message = recovery_message(recovery_.phase(), message);
  if (report) {
    s.iterations = report->iterations;
    s.solve_time = report->solve_time;
    s.max_constraint_violation = std::isfinite(report->max_violation) ? report->max_violation : 1e9;
    s.cost = std::isfinite(report->cost) ? report->cost : 0.0;
    s.warm_started = report->warm_started;
  }
  s.map_utime = field_valid_ ? field_map_utime_ : 0;
  node_.publish(channels::kSolverStats, s);
}

void RhOptimizerService::tick() {
  const Utime now = node_.now();
  auto note = [&](const std::string& text) {
    if (text != last_note_) node_.set_state(text);
    last_note_ = text;
  };
  if (!mission_ || !nav_) return note("waiting for mission and nav");
  if (now - nav_->utime > to_utime(config_.nav_max_age)) {
    note("nav stale");
    return publish_stats(now, solver_stats_t::NOT_RUN, "nav stale", nullptr);
  }
  const Vec3 position = to_vec3(nav_->position);
  const Vec3 velocity = to_vec3(nav_->velocity);
  if (!legs_.has_plan()) legs_.set_plan(mission_->mission_id, waypoints_from(*mission_), position);
  const auto active = legs_.update(position);
  if (!active) return note("no leg");
  if (active->index != active_leg_) {
    // A new leg is a new guidance frame: the previous solution is no guess.
    active_leg_ = active->index;
    planner_.reset();
    recovery_.reset();
    route_changed_ = true;
  }
  if (!grid_ || now - grid_->utime > to_utime(config_.grid_max_age)) {
    // Blind: no decisions on a map that is not there. An engaged avoidance
    // keeps its last trajectory until the controller times it out.
    note("no fresh obstacle grid");
    return publish_stats(now, solver_stats_t::NOT_RUN, "no fresh obstacle grid", nullptr);
  }
  // A map fed by a trickle of scans is as blind as none: no plans, and
  // guidance holds (PerceptionWatch); the controller flies the last plan's
  // stop.
  if (scan_supply_.starved(to_seconds(now))) {
    if (!scans_starved_)
      node_.log().warn("map starved of scans at t={:.2f} s ({}): no plans until fed again",
                       to_seconds(now), scan_supply_.why());
    scans_starved_ = true;
    note("map starved of scans");
    return publish_stats(now, solver_stats_t::NOT_RUN,
                         "map starved of scans: " + scan_supply_.why(), nullptr);
  }
  if (scans_starved_) {
    node_.log().info("map fed again at t={:.2f} s ({:.0f} % of the scans arrive)", to_seconds(now),
                     100.0 * scan_supply_.share());
    scans_starved_ = false;
  }
  refresh_field(now, position);

  Limits limits = limits_from(mission_->limits);
  limits.clearance += tracking_widening(now);
  const Leg leg{active->from, active->to};
  const ClearanceQuery clearance = [this](const Vec3& p) { return field_.query(p); };
  const double required = limits.clearance + config_.avoidance.engage_margin;
  const NominalCheck nominal = check_nominal_path(clearance, leg, position, limits.sensor_range,
                                                  required, config_.avoidance);
  const bool conflict = std::isfinite(nominal.conflict_distance);
  const bool was_engaged = switch_.engaged();
  const double t = to_seconds(now);
  const double stopping_speed = stopping_at_target_ ? velocity.norm() : 0.0;
  // Only while the plan stops there, so that the switch asks for rest
  // (stopping_speed): handed back at speed so near, guidance overshoots.
  const bool at_last_waypoint = stopping_at_target_ && active->final &&
                                (position - active->to).norm() <= active->capture_radius;
  const bool engaged = switch_.update(t, conflict, cross_track_distance(leg, position),
                                      stopping_speed, at_last_waypoint);
  const RecoveryDecision recovery = update_recovery(now, leg, limits, position, velocity, engaged);
  if (!engaged) {
    if (was_engaged) {
      hand_back(now, position, velocity, "nominal path clear, back on the leg");
    } else if (++ticks_since_nominal_ >= static_cast<int64_t>(std::ceil(config_.rate))) {
      // Once a second while guidance is clear: a controller left flying the
      // stop of a plan from an optimiser that has since died and restarted
      // learns that guidance may resume.
      publish_nominal(now, position, velocity);
      ticks_since_nominal_ = 0;
    }
    note("nominal guidance");
    return publish_stats(now, solver_stats_t::NOT_RUN, "nominal guidance: path clear", nullptr,
                         true);
  }
  if (!was_engaged)
    node_.log().info(
        "avoidance engages at t={:.2f} s: nominal path clearance {:.1f} m < {:.1f} m, {:.1f} m "
        "ahead",
        t, nominal.least_clearance, required, nominal.conflict_distance);

  StepInput in;
  // On the last plan while the vehicle is near it, else at the measured
  // state (start_state.hpp).
  StartStateSettings start_rules;
  start_rules.planned_initial_state = config_.planned_initial_state;
  start_rules.replan_position_error = config_.replan_position_error;
  start_rules.replan_velocity_error = config_.replan_velocity_error;
  start_rules.planned_initial_acceleration = config_.planned_initial_acceleration;
  start_rules.stop_recapture_error = config_.stop_recapture_error;
  const StartState start = choose_start_state(
      last_trajectory_, last_trajectory_kind_, to_seconds(now - last_trajectory_t0_),
      MeasuredState{position, velocity, to_vec3(nav_->acceleration)}, mission_->limits.max_accel,
      start_rules);
  FramingSettings framing;
  framing.clearance_margin = config_.optimizer.clearance_margin;
  framing.pinch_clearance = pinch_clearance(limits);
  framing.max_shift = config_.passages.max_shift;
  in.problem =
      leg_problem(leg, active->final, start, position, limits, clearance, heightfield_, framing);
  RhProblem& p = in.problem;
  stopping_at_target_ = p.stop_at_target;
  in.time = t;
  if (!route_.empty() && now - route_utime_ <= to_utime(config_.path_max_age))
    in.global_path = route_;
  in.global_path_changed = route_changed_;
  route_changed_ = false;

  if (recovery.phase == RecoveryPhase::kLooking || recovery.phase == RecoveryPhase::kTurning ||
      recovery.phase == RecoveryPhase::kNoRoute) {
    // Hover where the stop from the state flown ends; while looking (or
    // turning to an escape leg), the controller turns the heading.
    const bool looking = recovery.phase != RecoveryPhase::kNoRoute;
    const BsplineTrajectory hover = planner_.braking_trajectory(p);
    const Utime t0 = to_utime(t);
    const int8_t mode = !looking             ? ref_traj_t::BRAKING
                        : recovery.turn_left ? ref_traj_t::LOOK_AROUND_LEFT
                                             : ref_traj_t::LOOK_AROUND;
    node_.publish(channels::kRefTraj,
                  trajectory_message(hover, t0, mode, config_.sample_period, now));
    last_trajectory_ = hover;
    last_trajectory_kind_ = LastPlan::kStop;
    last_trajectory_t0_ = t0;
    last_step_moving_ = false;
    note(std::string("recovery: ") + to_string(recovery.phase));
    return publish_stats(now, looking ? solver_stats_t::LOOKING_AROUND : solver_stats_t::NO_ROUTE,
                         std::string("recovery: ") + to_string(recovery.phase), nullptr);
  }
  const bool escaping = recovery.phase == RecoveryPhase::kEscaping;
  if (escaping) {
    // The leg of the escape: from where it began to where the route turns
    // forward again, along the route; the forward-speed rule of Eq. 8 is
    // relaxed (the route may bend back), the commit gate is not.
    frame_escape(&p, recovery.escape_from, recovery.escape_point, position, heightfield_, framing);
    stopping_at_target_ = false;
    in.global_path = recovery.escape_route;
  }
  if (config_.occlusion_depth > 0)
    in.seen = [this](double north, double east) { return visibility_.seen(north, east); };

  // A climb to look over what the scanner saw from below, straight up from
  // the hover the look left; the controller turns the heading on the way,
  // so the scanner looks all round at every altitude it passes.
  const bool climbing = recovery.phase == RecoveryPhase::kClimbing;
  const StepOutput out =
      climbing ? planner_.climb(in, -(config_.optimizer.ground_altitude + recovery.climb_altitude))
               : planner_.step(in);
  ++steps_;
  // A plan that moves off, not a stop, a stall or a hover in place: the
  // recovery counts the vehicle stuck without one.
  last_step_moving_ = plan_moves_off(out, 2.0 * config_.recovery.capture_radius);
  // Deferring leaves the vehicle to nominal guidance: only before this
  // engagement has published anything. Once a plan or a stop has been
  // flown, the controller holds to it (and to its stop) and a silence
  // would only leave it hovering.
  if (out.mode == StepMode::kBraking && last_trajectory_.empty() &&
      defer_first_brake(nominal.conflict_distance, velocity,
                        config_.fallback.braking_accel_fraction * limits.max_accel,
                        config_.defer_margin)) {
    note("avoidance deferred: no trajectory yet");
    return publish_stats(now, solver_stats_t::DEFERRED,
                         "no avoidance trajectory yet (" + out.reason +
                             "); conflict still far, nominal guidance continues",
                         &out.report, true);
  }
  const Utime t0 = to_utime(out.start_time);
  const int8_t mode =
      climbing && out.mode == StepMode::kSolved ? ref_traj_t::LOOK_AROUND : traj_mode(out.mode);
  node_.publish(channels::kRefTraj,
                trajectory_message(out.trajectory, t0, mode, config_.sample_period, now));
  last_trajectory_ = out.trajectory;
  last_trajectory_kind_ = out.mode == StepMode::kBraking ? LastPlan::kStop : LastPlan::kMoving;
  last_trajectory_t0_ = t0;
  std::string message = recovery_message(recovery.phase, to_string(out.mode));
  if (!out.reason.empty()) message += ": " + out.reason;
  if (out.mode == StepMode::kSolved && out.refused > 0)
    message += (out.reason.empty() ? ": " : "; ") + std::string("the commit gate refused ") +
               std::to_string(out.refused) + " other plan(s) (" + out.refusal + ")";
  if (out.mode != StepMode::kSolved) {
    // One line per streak of like steps (the first in full, then a
    // summary); every step's message still goes out in SOLVER_STATS.
    step_warned_ = true;
    const std::string text = fmt::format("t={:.2f} s {} ({} solves, worst violation {:.3g})", t,
                                         message, out.solves, out.report.max_violation);
    for (const std::string& line :
         warning_streak_.warn(t, recovery_message(recovery.phase, to_string(out.mode)), text,
                              out.report.max_violation))
      node_.log().warn("{}", line);
  } else if (out.refused > 0)
    node_.log().info("t={:.2f} s {}", t, message);
  else if (out.stalled != stalled_)
    node_.log().info("t={:.2f} s {}", t, out.stalled ? message : "no longer stalled");
  stalled_ = out.stalled;
  note(std::string("avoiding: ") + to_string(out.mode));
  publish_stats(now, stats_status(out.mode), message, &out.report);
}

}  // namespace ofn::rh
