#include "ofn/fuzz/message_support.hpp"

#include <unistd.h>

#include "ofn/actuator_cmd_t.hpp"
#include "ofn/bus_auth/trailer.hpp"
#include "ofn/common/validate.hpp"
#include "ofn/control_status_t.hpp"
#include "ofn/cuboid_list_t.hpp"
#include "ofn/global_path_t.hpp"
#include "ofn/heartbeat_t.hpp"
#include "ofn/lidar_scan_t.hpp"
#include "ofn/mission_t.hpp"
#include "ofn/narrow_passages_t.hpp"
#include "ofn/nav_state_t.hpp"
#include "ofn/obstacle_grid_t.hpp"
#include "ofn/ref_traj_t.hpp"
#include "ofn/scan_world_t.hpp"
#include "ofn/scanner_status_t.hpp"
#include "ofn/sim_clock_t.hpp"
#include "ofn/solver_stats_t.hpp"
#include "ofn/virtual_obstacles_t.hpp"

namespace ofn::fuzz {
namespace {

// The seeds: one valid message of each type, small (a few elements in
// every array), and a little off the flight's own values, so that a seed
// that a receiver took would be seen. Every field is set: each is a place
// the fuzz puts its values.

nav_state_t seed_nav_state() {
  nav_state_t m{};
  m.frame = "NED";
  const double p[3] = {12.5, -3.25, -36.5}, v[3] = {3.0, 0.25, -0.125};
  for (int i = 0; i < 3; ++i) {
    m.position[i] = p[i];
    m.velocity[i] = v[i];
    m.acceleration[i] = 0.01 * (i + 1);
    m.euler[i] = 0.001 * (i + 1);
    m.body_rates[i] = -0.002 * (i + 1);
  }
  m.quaternion[0] = 1.0;
  return m;
}

actuator_cmd_t seed_actuator_cmd() {
  actuator_cmd_t m{};
  m.collective = 0.1;
  m.lon_cyclic = 0.01;
  m.lat_cyclic = -0.01;
  m.pedal = 0.02;
  return m;
}

sim_clock_t seed_sim_clock() {
  sim_clock_t m{};
  m.real_time_factor = 1.0;
  m.step = 1000;
  return m;
}

mission_t seed_mission() {
  mission_t m{};
  m.mission_id = 7;
  m.name = "fuzz";
  m.frame = "NED";
  m.cruise_speed = 2.5;
  m.limits.max_speed = 3.0;
  m.limits.max_accel = 1.0;
  m.limits.max_vertical_speed = 1.5;
  m.limits.min_forward_speed = 0.0;
  m.limits.clearance = 6.0;
  m.limits.sensor_range = 60.0;
  for (int i = 0; i < 2; ++i) {
    waypoint_t w{};
    w.position[0] = 20.0 * i;
    w.position[1] = 1.0;
    w.position[2] = -30.0;
    w.capture_radius = 3.0;
    m.waypoints.push_back(w);
  }
  m.num_waypoints = 2;
  return m;
}

virtual_obstacles_t seed_virtual_obstacles() {
  virtual_obstacles_t m{};
  m.revision = 3;
  m.ground_altitude = 0.5;
  for (int i = 0; i < 2; ++i) {
    obstacle_t o{};
    o.id = i + 1;
    o.kind = i == 0 ? obstacle_t::BOX : obstacle_t::CYLINDER;
    o.center[0] = 300.0 + 10 * i;
    o.center[1] = 200.0;
    o.size[0] = o.size[1] = 4.0;
    o.height = 10.0;
    o.yaw = 0.1;
    o.seed = 5;
    o.appear_time = -1.0;
    o.disappear_time = -1.0;
    m.obstacles.push_back(o);
  }
  m.num_obstacles = 2;
  return m;
}

lidar_scan_t seed_lidar_scan() {
  lidar_scan_t m{};
  m.scan_index = 11;
  m.max_range = 100.0;
  m.num_beams = 3;
  for (int i = 0; i < 3; ++i) {
    m.beam_dt_us.push_back(100 * i);
    m.elevation.push_back(-0.2f + 0.1f * static_cast<float>(i));
    m.layer_angle.push_back(0.0f);
    m.range.push_back(40.0f + static_cast<float>(i));
    m.status.push_back(lidar_scan_t::OK);
  }
  return m;
}

scan_world_t seed_scan_world() {
  scan_world_t m{};
  m.scan_index = 11;
  m.frame = "NED";
  m.sensor_origin[2] = -36.0;
  m.num_points = 2;
  m.points = {{50.0f, 1.0f, -0.5f}, {51.0f, 1.5f, -0.25f}};
  m.num_free_rays = 1;
  m.free_ray_ends = {{90.0f, 2.0f, -30.0f}};
  m.num_rejected = 1;
  return m;
}

scanner_status_t seed_scanner_status() {
  scanner_status_t m{};
  m.scan_index = 11;
  m.beams = 3;
  m.returns = 2;
  return m;
}

obstacle_grid_t seed_obstacle_grid() {
  obstacle_grid_t m{};
  m.frame = "NED";
  m.origin[0] = 400.0;
  m.origin[1] = 300.0;
  m.resolution = 1.0;
  m.safety_margin = 2.0;
  m.rows = 2;
  m.cols = 2;
  m.num_cells = 4;
  m.top_altitude = {0.0f, 1.5f, 0.0f, 2.5f};
  return m;
}

cuboid_list_t seed_cuboid_list() {
  cuboid_list_t m{};
  m.frame = "NED";
  for (int i = 0; i < 2; ++i) {
    cuboid_t c{};
    c.id = i + 1;
    c.min_corner[0] = 400.0 + 10 * i;
    c.min_corner[1] = 300.0;
    c.min_corner[2] = -8.0;
    c.max_corner[0] = c.min_corner[0] + 3.0;
    c.max_corner[1] = 303.0;
    c.max_corner[2] = 0.0;
    c.top_observed = i == 0;
    c.confidence = 0.75;
    m.cuboids.push_back(c);
  }
  m.num_cuboids = 2;
  return m;
}

global_path_t seed_global_path() {
  global_path_t m{};
  m.frame = "NED";
  m.status = global_path_t::OK;
  m.cost = 120.0;
  m.num_points = 3;
  m.points = {{0.0, 0.0, -30.0}, {60.0, 5.0, -30.0}, {120.0, 0.0, -30.0}};
  return m;
}

narrow_passages_t seed_narrow_passages() {
  narrow_passages_t m{};
  m.frame = "NED";
  m.mission_id = 7;
  m.num_passages = 1;
  m.centre = {{450.0, 320.0, -20.0}};
  m.radius = {2.0};
  m.half_height = {5.0};
  return m;
}

ref_traj_t seed_ref_traj() {
  // A clamped cubic spline and three samples, far from any course's
  // start: (400, 300) m.
  ref_traj_t m{};
  m.frame = "NED";
  m.mode = ref_traj_t::AVOIDANCE;
  m.degree = 3;
  m.num_control_points = 4;
  for (int i = 0; i < 4; ++i) m.control_points.push_back({400.0 + i, 300.0, -30.0});
  m.num_knots = 8;
  m.knots = {0.0, 0.0, 0.0, 0.0, 2.0, 2.0, 2.0, 2.0};
  m.num_samples = 3;
  m.sample_time = {0.0, 1.0, 2.0};
  for (int i = 0; i < 3; ++i) {
    m.position.push_back({400.0 + 1.5 * i, 300.0, -30.0});
    m.velocity.push_back({1.5, 0.0, 0.0});
    m.acceleration.push_back({0.0, 0.0, 0.0});
  }
  return m;
}

solver_stats_t seed_solver_stats() {
  solver_stats_t m{};
  m.status = solver_stats_t::NOT_RUN;
  m.message = "fuzz";
  m.iterations = 3;
  m.solve_time = 0.004;
  m.max_constraint_violation = 0.001;
  m.cost = 12.5;
  m.warm_started = true;
  m.guidance_clear = false;
  m.mission_id = 7;
  m.active_waypoint = 1;
  return m;
}

control_status_t seed_control_status() {
  control_status_t m{};
  m.mode = control_status_t::WAYPOINT;
  m.mission_id = 7;
  m.active_waypoint = 1;
  for (int i = 0; i < 3; ++i) {
    m.ref_position[i] = i == 2 ? -30.0 : 5.0 * i;
    m.ref_velocity[i] = 0.5;
    m.ref_acceleration[i] = 0.01;
    m.commanded_acceleration[i] = 0.02;
    m.position_error[i] = 0.1;
    m.adaptive_output[i] = 0.001;
  }
  m.yaw_reference = 0.2;
  m.ref_traj_fresh = false;
  return m;
}

heartbeat_t seed_heartbeat() {
  // The fuzz's own name and pid: a reader of the bus can tell these from
  // the services' own.
  heartbeat_t m{};
  m.service = "fuzz";
  m.pid = static_cast<int32_t>(::getpid());
  m.state = "running";
  m.received = 10;
  m.rejected = 2;
  m.late = 1;
  m.unauthenticated = 1;
  m.last_reject_reason = "fuzz";
  m.loop_time_mean = 0.0001;
  m.loop_time_max = 0.001;
  m.cpu_fraction = 0.01;
  m.uptime = 5.0;
  return m;
}

template <class Msg>
std::vector<uint8_t> encode(const Msg& m) {
  std::vector<uint8_t> bytes(static_cast<size_t>(m.getEncodedSize()));
  m.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  return bytes;
}

template <class Msg>
MessageSupport support(Msg (*make)()) {
  MessageSupport s;
  s.type = Msg::getTypeName();
  s.fingerprint = Msg::getHash();
  s.seed = [make] { return encode(make()); };
  s.check = [](const uint8_t* data, size_t size) -> std::string {
    Msg m;
    if (!bus_auth::decode_payload(m, data, size)) return "undecodable";
    return validate(m);
  };
  s.reencode = [](const uint8_t* data, size_t size) -> std::optional<std::vector<uint8_t>> {
    Msg m;
    if (!bus_auth::decode_payload(m, data, size)) return std::nullopt;
    return encode(m);
  };
  s.subscribe = [](Node& node, const std::string& channel, SubscribeOptions options,
                   std::function<void()> on_accepted) {
    node.subscribe<Msg>(
        channel, [on_accepted](const Msg&) { on_accepted(); }, options);
  };
  return s;
}

}  // namespace

const std::vector<MessageSupport>& message_supports() {
  static const std::vector<MessageSupport> table = {
      support(&seed_nav_state),   support(&seed_actuator_cmd),      support(&seed_sim_clock),
      support(&seed_mission),     support(&seed_virtual_obstacles), support(&seed_lidar_scan),
      support(&seed_scan_world),  support(&seed_scanner_status),    support(&seed_obstacle_grid),
      support(&seed_cuboid_list), support(&seed_global_path),       support(&seed_narrow_passages),
      support(&seed_ref_traj),    support(&seed_solver_stats),      support(&seed_control_status),
      support(&seed_heartbeat),
  };
  return table;
}

const MessageSupport* find_message_support(const std::string& type) {
  for (const auto& s : message_supports())
    if (s.type == type) return &s;
  return nullptr;
}

}  // namespace ofn::fuzz
