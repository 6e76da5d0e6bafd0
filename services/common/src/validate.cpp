#include "ofn/common/validate.hpp"

#include <algorithm>
#include <vector>

#include "ofn/common/message_names.hpp"
#include "ofn/common/ref_traj_sample.hpp"

namespace ofn {
namespace {

const char* kFrame = "NED";

bool within_world(const double (&p)[3]) {
  return all_finite(p) && std::abs(p[0]) < MessageLimits::kMaxCoordinate &&
         std::abs(p[1]) < MessageLimits::kMaxCoordinate &&
         std::abs(p[2]) < MessageLimits::kMaxCoordinate;
}

// A point of a scan: three floats within the world.
bool within_world(const std::vector<float>& p) {
  return p.size() == 3 && all_finite(p.begin(), p.end()) &&
         std::abs(p[0]) < MessageLimits::kMaxCoordinate &&
         std::abs(p[1]) < MessageLimits::kMaxCoordinate &&
         std::abs(p[2]) < MessageLimits::kMaxCoordinate;
}

std::string check_count(int32_t count, size_t actual, int32_t max, const char* what) {
  if (count < 0) return std::string("negative ") + what + " count";
  if (count > max)
    return std::string("too many ") + what + " (" + std::to_string(count) + " > " +
           std::to_string(max) + ")";
  if (static_cast<size_t>(count) != actual) return std::string(what) + " count does not match";
  return "";
}

std::string check_frame(const std::string& frame) {
  return frame == kFrame ? "" : "frame '" + printable(frame, 16) + "' is not NED";
}

}  // namespace

std::string validate(const nav_state_t& m) {
  if (auto e = check_frame(m.frame); !e.empty()) return e;
  if (!within_world(m.position)) return "position not finite or out of range";
  if (!all_finite(m.velocity) || !all_finite(m.acceleration))
    return "velocity/acceleration not finite";
  if (!all_finite(m.quaternion) || !all_finite(m.euler) || !all_finite(m.body_rates))
    return "attitude not finite";
  const double qn =
      std::sqrt(m.quaternion[0] * m.quaternion[0] + m.quaternion[1] * m.quaternion[1] +
                m.quaternion[2] * m.quaternion[2] + m.quaternion[3] * m.quaternion[3]);
  if (std::abs(qn - 1.0) > 1e-3) return "quaternion not normalised";
  return "";
}

std::string validate(const actuator_cmd_t& m) {
  const double v[4] = {m.collective, m.lon_cyclic, m.lat_cyclic, m.pedal};
  if (!all_finite(v)) return "actuator command not finite";
  for (double x : v)
    if (std::abs(x) > 1.0) return "actuator command beyond 1 rad";
  return "";
}

std::string validate(const sim_clock_t& m) {
  if (m.utime < 0) return "negative simulation time";
  if (!std::isfinite(m.real_time_factor) || m.real_time_factor <= 0) return "bad real-time factor";
  return "";
}

std::string validate(const mission_t& m) {
  if (auto e = check_frame(m.frame); !e.empty()) return e;
  if (auto e = check_count(m.num_waypoints, m.waypoints.size(), MessageLimits::kMaxWaypoints,
                           "waypoints");
      !e.empty())
    return e;
  const auto& l = m.limits;
  const double lim[6] = {l.max_speed,         l.max_accel, l.max_vertical_speed,
                         l.min_forward_speed, l.clearance, l.sensor_range};
  if (!all_finite(lim)) return "limits not finite";
  if (l.max_speed <= 0 || l.max_accel <= 0 || l.max_vertical_speed <= 0)
    return "limits not positive";
  if (l.clearance < 0 || l.sensor_range < 0) return "negative clearance or sensor range";
  if (!(m.cruise_speed > 0) || m.cruise_speed > l.max_speed * (1 + 1e-9))
    return "cruise speed not in (0, max_speed]";
  for (const auto& wp : m.waypoints) {
    if (!within_world(wp.position)) return "waypoint not finite or out of range";
    if (!(wp.capture_radius > 0) || !std::isfinite(wp.capture_radius))
      return "waypoint capture radius not positive";
  }
  return "";
}

std::string validate(const virtual_obstacles_t& m) {
  if (auto e = check_count(m.num_obstacles, m.obstacles.size(), MessageLimits::kMaxObstacles,
                           "obstacles");
      !e.empty())
    return e;
  if (!std::isfinite(m.ground_altitude)) return "ground altitude not finite";
  for (const auto& o : m.obstacles) {
    if (o.kind < obstacle_t::BOX || o.kind > obstacle_t::TREE) return "unknown obstacle kind";
    const double v[5] = {o.center[0], o.center[1], o.size[0], o.size[1], o.height};
    if (!all_finite(v) || !std::isfinite(o.yaw)) return "obstacle not finite";
    // Negative is "always there" / "never goes"; NaN would be neither.
    if (!std::isfinite(o.appear_time) || !std::isfinite(o.disappear_time))
      return "obstacle schedule not finite";
    if (o.size[0] <= 0 || o.size[1] <= 0 || o.height <= 0) return "obstacle size not positive";
  }
  return "";
}

std::string validate(const lidar_scan_t& m) {
  const size_t n = m.range.size();
  if (auto e = check_count(m.num_beams, n, MessageLimits::kMaxBeams, "beams"); !e.empty()) return e;
  if (m.beam_dt_us.size() != n || m.elevation.size() != n || m.layer_angle.size() != n ||
      m.status.size() != n)
    return "beam arrays differ in length";
  if (!(m.max_range > 0) || !(m.max_range < MessageLimits::kMaxCoordinate))
    return "max range not positive or beyond the world";
  if (!all_finite(m.elevation.begin(), m.elevation.end()) ||
      !all_finite(m.layer_angle.begin(), m.layer_angle.end()))
    return "beam angle not finite";
  for (size_t i = 0; i < n; ++i) {
    if (m.status[i] < lidar_scan_t::OK || m.status[i] > lidar_scan_t::MAX_RANGE)
      return "unknown beam status";
    // A range is only meaningful on an OK beam; a NaN there is a corrupt scan.
    if (m.status[i] == lidar_scan_t::OK && !(std::isfinite(m.range[i]) && m.range[i] >= 0))
      return "range not finite";
    if (m.beam_dt_us[i] < 0) return "negative beam time offset";
  }
  return "";
}

std::string validate(const scanner_status_t& m) {
  if (m.beams < 0 || m.beams > MessageLimits::kMaxBeams) return "beam count out of range";
  if (m.returns < 0 || m.returns > m.beams) return "returns not between 0 and the beams";
  return "";
}

std::string validate(const scan_world_t& m) {
  if (auto e = check_frame(m.frame); !e.empty()) return e;
  if (auto e = check_count(m.num_points, m.points.size(), MessageLimits::kMaxScanPoints, "points");
      !e.empty())
    return e;
  if (!within_world(m.sensor_origin)) return "sensor origin not finite";
  for (const auto& p : m.points)
    if (!within_world(p)) return "point not finite or out of range";
  if (auto e = check_count(m.num_free_rays, m.free_ray_ends.size(), MessageLimits::kMaxScanPoints,
                           "free rays");
      !e.empty())
    return e;
  for (const auto& p : m.free_ray_ends)
    if (!within_world(p)) return "free ray end not finite or out of range";
  if (m.num_rejected < 0) return "negative rejected count";
  return "";
}

std::string validate(const obstacle_grid_t& m) {
  if (auto e = check_frame(m.frame); !e.empty()) return e;
  if (m.rows <= 0 || m.cols <= 0) return "grid dimensions not positive";
  if (static_cast<int64_t>(m.rows) * m.cols != m.num_cells) return "cell count != rows * cols";
  if (auto e =
          check_count(m.num_cells, m.top_altitude.size(), MessageLimits::kMaxGridCells, "cells");
      !e.empty())
    return e;
  if (!(m.resolution >= MessageLimits::kMinGridResolution &&
        m.resolution <= MessageLimits::kMaxGridResolution))
    return "resolution outside 0.05..20 m";
  if (!all_finite(m.origin) || !std::isfinite(m.safety_margin)) return "grid geometry not finite";
  if (std::abs(m.origin[0]) >= MessageLimits::kMaxCoordinate ||
      std::abs(m.origin[1]) >= MessageLimits::kMaxCoordinate ||
      !(m.safety_margin >= 0 && m.safety_margin < MessageLimits::kMaxCoordinate))
    return "grid origin or margin out of range";
  if (!all_finite(m.top_altitude.begin(), m.top_altitude.end())) return "cell not finite";
  return "";
}

std::string validate(const cuboid_list_t& m) {
  if (auto e = check_frame(m.frame); !e.empty()) return e;
  if (auto e = check_count(m.num_cuboids, m.cuboids.size(), MessageLimits::kMaxCuboids, "cuboids");
      !e.empty())
    return e;
  for (const auto& c : m.cuboids) {
    if (!within_world(c.min_corner) || !within_world(c.max_corner)) return "cuboid not finite";
    if (!std::isfinite(c.confidence)) return "cuboid confidence not finite";
    for (int k = 0; k < 3; ++k)
      if (c.min_corner[k] > c.max_corner[k]) return "cuboid min corner above max corner";
  }
  return "";
}

std::string validate(const global_path_t& m) {
  if (auto e = check_frame(m.frame); !e.empty()) return e;
  if (auto e = check_count(m.num_points, m.points.size(), MessageLimits::kMaxPathPoints, "points");
      !e.empty())
    return e;
  if (m.status < global_path_t::OK || m.status > global_path_t::BACKTRACK) return "unknown status";
  if (!std::isfinite(m.cost)) return "path cost not finite";
  for (const auto& p : m.points)
    if (p.size() != 3 || !all_finite(p.begin(), p.end())) return "path point not finite";
  return "";
}

std::string validate(const narrow_passages_t& m) {
  if (auto e = check_frame(m.frame); !e.empty()) return e;
  if (auto e =
          check_count(m.num_passages, m.centre.size(), MessageLimits::kMaxPassages, "passages");
      !e.empty())
    return e;
  if (m.radius.size() != m.centre.size() || m.half_height.size() != m.centre.size())
    return "passage arrays differ in length";
  for (size_t i = 0; i < m.centre.size(); ++i) {
    const auto& c = m.centre[i];
    if (c.size() != 3 || !all_finite(c.begin(), c.end()) ||
        std::abs(c[0]) >= MessageLimits::kMaxCoordinate ||
        std::abs(c[1]) >= MessageLimits::kMaxCoordinate ||
        std::abs(c[2]) >= MessageLimits::kMaxCoordinate)
      return "passage centre not finite or out of range";
    if (!std::isfinite(m.radius[i]) || !std::isfinite(m.half_height[i]) || m.radius[i] <= 0 ||
        m.half_height[i] <= 0)
      return "passage size not finite and positive";
  }
  return "";
}

std::string validate(const ref_traj_t& m) {
  if (auto e = check_frame(m.frame); !e.empty()) return e;
  if (auto e = check_count(m.num_samples, m.sample_time.size(), MessageLimits::kMaxTrajSamples,
                           "samples");
      !e.empty())
    return e;
  if (m.mode < ref_traj_t::NOMINAL || m.mode > ref_traj_t::LOOK_AROUND_LEFT) return "unknown mode";
  const size_t n = m.sample_time.size();
  if (m.position.size() != n || m.velocity.size() != n || m.acceleration.size() != n)
    return "sample arrays differ in length";
  if (auto e = check_count(m.num_knots, m.knots.size(), MessageLimits::kMaxSplineKnots, "knots");
      !e.empty())
    return e;
  if (auto e = check_count(m.num_control_points, m.control_points.size(),
                           MessageLimits::kMaxSplineKnots, "control points");
      !e.empty())
    return e;
  if (m.num_control_points > 0) {
    // A clamped B-spline over [0, T] s from t0, as the RH optimiser sends:
    // receivers sample it (expand_ref_traj), so it must be one.
    if (m.degree < 1 || m.degree > 7) return "spline degree outside 1..7";
    if (m.num_control_points < m.degree + 1) return "fewer control points than degree + 1";
    if (m.num_knots != m.num_control_points + m.degree + 1)
      return "knot count != control points + degree + 1";
    if (!all_finite(m.knots.begin(), m.knots.end())) return "knot not finite";
    for (size_t i = 1; i < m.knots.size(); ++i)
      if (m.knots[i] < m.knots[i - 1]) return "knots decrease";
    const double end = m.knots.back();
    if (!(end > 0.0) || end > MessageLimits::kMaxTrajSamples * kRefTrajSamplePeriod)
      return "spline duration outside (0, " +
             std::to_string(MessageLimits::kMaxTrajSamples * kRefTrajSamplePeriod) + "] s";
    for (int i = 0; i <= m.degree; ++i)
      if (m.knots[static_cast<size_t>(i)] != 0.0 || m.knots[m.knots.size() - 1 - i] != end)
        return "spline not clamped at 0 and its end";
    for (const auto& p : m.control_points) {
      if (p.size() != 3 || !all_finite(p.begin(), p.end())) return "control point not finite";
      for (double c : p)
        if (std::abs(c) > MessageLimits::kMaxCoordinate) return "control point out of range";
    }
  } else if (m.num_knots != 0) {
    return "knots without control points";
  }
  if (n == 0 && m.num_control_points == 0) return "neither samples nor a spline";
  if (n == 1) return "fewer than two samples";
  if (!all_finite(m.sample_time.begin(), m.sample_time.end())) return "sample time not finite";
  for (size_t i = 1; i < n; ++i)
    if (!(m.sample_time[i] > m.sample_time[i - 1])) return "sample times not increasing";
  for (size_t i = 0; i < n; ++i) {
    for (const auto* v : {&m.position[i], &m.velocity[i], &m.acceleration[i]})
      if (v->size() != 3 || !all_finite(v->begin(), v->end())) return "sample not finite";
  }
  return "";
}

std::string validate(const solver_stats_t& m) {
  const double v[3] = {m.solve_time, m.max_constraint_violation, m.cost};
  if (!all_finite(v)) return "statistics not finite";
  if (m.active_waypoint < -1) return "active waypoint below -1";
  // The map a status was checked on is older than the status; a map stamp
  // ahead of it would count as fresh for that long (the controller's
  // PerceptionWatch lets guidance fly on a fresh map).
  // 1 s allows for the hosts' clocks, as a node's max_future does.
  constexpr int64_t kMapAheadOfStatus = 1000000;  // us
  if (m.map_utime > m.utime + kMapAheadOfStatus)
    return "map stamped more than 1 s after the status";
  return "";
}

std::string validate(const control_status_t& m) {
  if (!all_finite(m.ref_position) || !all_finite(m.ref_velocity) ||
      !all_finite(m.ref_acceleration) || !all_finite(m.commanded_acceleration) ||
      !all_finite(m.position_error) || !all_finite(m.adaptive_output) ||
      !std::isfinite(m.yaw_reference))
    return "status not finite";
  if (m.active_waypoint < -1) return "active waypoint below -1";
  return "";
}

std::string validate(const heartbeat_t& m) {
  if (m.service.empty()) return "no service name";
  if (m.unauthenticated < 0 || m.unauthenticated > m.rejected)
    return "unauthenticated count outside 0..rejected";
  const double v[4] = {m.loop_time_mean, m.loop_time_max, m.cpu_fraction, m.uptime};
  if (!all_finite(v)) return "loop times, CPU or uptime not finite";
  for (const auto& input : m.inputs) {
    if (input.channel.empty()) return "an input without a channel name";
    if (input.received < 0 || input.lost < 0 || input.duplicated < 0 || input.publishers < 0 ||
        input.unsequenced < 0 || input.unsequenced > input.received ||
        input.duplicated > input.received)
      return "input counts negative or above the received";
  }
  return "";
}

}  // namespace ofn
