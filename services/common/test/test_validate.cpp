// Message content checks: every service relies on these to keep bad input
// away from its handlers.

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "ofn/common/validate.hpp"

namespace ofn {
namespace {

constexpr double kNaNValue = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

nav_state_t good_nav() {
  nav_state_t m{};
  m.utime = 1000;
  m.frame = "NED";
  m.position[0] = 10;
  m.position[2] = -30;
  m.velocity[0] = 3;
  m.quaternion[0] = 1.0;
  return m;
}

actuator_cmd_t good_cmd() {
  actuator_cmd_t m{};
  m.utime = 1000;
  m.collective = 0.15;
  m.lon_cyclic = -0.02;
  m.lat_cyclic = 0.01;
  m.pedal = 0.1;
  return m;
}

mission_t good_mission() {
  mission_t m{};
  m.utime = 1000;
  m.mission_id = 1;
  m.name = "test";
  m.frame = "NED";
  m.cruise_speed = 3.0;
  m.limits.max_speed = 3.0;
  m.limits.max_accel = 0.5;
  m.limits.max_vertical_speed = 1.0;
  m.limits.min_forward_speed = 0.0;
  m.limits.clearance = 6.0;
  m.limits.sensor_range = 60.0;
  for (double north : {0.0, 100.0}) {
    waypoint_t w{};
    w.position[0] = north;
    w.position[2] = -30;
    w.capture_radius = 3.0;
    m.waypoints.push_back(w);
  }
  m.num_waypoints = 2;
  return m;
}

lidar_scan_t good_scan() {
  lidar_scan_t m{};
  m.utime = 1000;
  m.max_range = 100.0;
  m.num_beams = 3;
  m.beam_dt_us = {0, 10, 20};
  m.elevation = {-0.1f, 0.0f, 0.1f};
  m.layer_angle = {0.0f, 0.0f, 0.0f};
  m.range = {10.0f, 0.0f, 100.0f};
  m.status = {lidar_scan_t::OK, lidar_scan_t::NO_RETURN, lidar_scan_t::MAX_RANGE};
  return m;
}

ref_traj_t good_traj() {
  ref_traj_t m{};
  m.utime = 1000;
  m.t0_utime = 1000;
  m.frame = "NED";
  m.mode = ref_traj_t::NOMINAL;
  m.degree = 3;
  m.num_knots = 0;
  m.num_control_points = 0;
  m.sample_time = {0.0, 0.5, 1.0};
  m.position = {{0, 0, -30}, {1, 0, -30}, {2, 0, -30}};
  m.velocity = {{2, 0, 0}, {2, 0, 0}, {2, 0, 0}};
  m.acceleration = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
  m.num_samples = 3;
  return m;
}

obstacle_grid_t good_grid() {
  obstacle_grid_t m{};
  m.utime = 1000;
  m.frame = "NED";
  m.resolution = 1.0;
  m.safety_margin = 2.0;
  m.rows = 2;
  m.cols = 3;
  m.num_cells = 6;
  m.top_altitude = {0, 0, 5, 5, 0, 0};
  return m;
}

sim_clock_t good_clock() {
  sim_clock_t m{};
  m.utime = 1000;
  m.real_time_factor = 1.0;
  m.step = 4;
  return m;
}

virtual_obstacles_t good_obstacles() {
  virtual_obstacles_t m{};
  m.utime = 1000;
  m.revision = 1;
  m.ground_altitude = 0.0;
  obstacle_t o{};
  o.id = 1;
  o.kind = obstacle_t::BOX;
  o.center[0] = 50;
  o.size[0] = 10;
  o.size[1] = 5;
  o.height = 20;
  o.appear_time = -1;
  o.disappear_time = -1;
  m.obstacles.push_back(o);
  m.num_obstacles = 1;
  return m;
}

scan_world_t good_scan_world() {
  scan_world_t m{};
  m.utime = 1000;
  m.frame = "NED";
  m.sensor_origin[2] = -30;
  m.points = {{10.0f, 0.0f, -20.0f}, {11.0f, 1.0f, -21.0f}};
  m.num_points = 2;
  return m;
}

cuboid_list_t good_cuboids() {
  cuboid_list_t m{};
  m.utime = 1000;
  m.frame = "NED";
  cuboid_t c{};
  c.id = 1;
  c.min_corner[0] = 40;
  c.min_corner[1] = -5;
  c.min_corner[2] = -20;
  c.max_corner[0] = 60;
  c.max_corner[1] = 5;
  c.max_corner[2] = 0;
  c.confidence = 1.0;
  m.cuboids.push_back(c);
  m.num_cuboids = 1;
  return m;
}

global_path_t good_path() {
  global_path_t m{};
  m.utime = 1000;
  m.frame = "NED";
  m.status = global_path_t::OK;
  m.cost = 100;
  m.points = {{0, 0, -30}, {100, 0, -30}};
  m.num_points = 2;
  return m;
}

solver_stats_t good_stats() {
  solver_stats_t m{};
  m.utime = 1000;
  m.status = solver_stats_t::SOLVED;
  m.message = "ok";
  m.iterations = 10;
  m.solve_time = 0.01;
  return m;
}

control_status_t good_status() {
  control_status_t m{};
  m.utime = 1000;
  m.mode = control_status_t::WAYPOINT;
  m.mission_id = 1;
  m.active_waypoint = 1;
  return m;
}

heartbeat_t good_heartbeat() {
  heartbeat_t m{};
  m.utime = 1000;
  m.service = "controller";
  m.state = "running";
  return m;
}

TEST(Validate, GoodMessagesOfEveryTypePass) {
  EXPECT_EQ(validate(good_nav()), "");
  EXPECT_EQ(validate(good_cmd()), "");
  EXPECT_EQ(validate(good_clock()), "");
  EXPECT_EQ(validate(good_mission()), "");
  EXPECT_EQ(validate(good_obstacles()), "");
  EXPECT_EQ(validate(good_scan()), "");
  EXPECT_EQ(validate(good_scan_world()), "");
  EXPECT_EQ(validate(good_grid()), "");
  EXPECT_EQ(validate(good_cuboids()), "");
  EXPECT_EQ(validate(good_path()), "");
  EXPECT_EQ(validate(good_traj()), "");
  EXPECT_EQ(validate(good_stats()), "");
  EXPECT_EQ(validate(good_status()), "");
  EXPECT_EQ(validate(good_heartbeat()), "");
}

TEST(Validate, NavStateRejectsNonFinitePosition) {
  for (int i = 0; i < 3; ++i) {
    nav_state_t m = good_nav();
    m.position[i] = kNaNValue;
    EXPECT_NE(validate(m), "") << "axis " << i;
    m.position[i] = kInf;
    EXPECT_NE(validate(m), "") << "axis " << i;
  }
}

TEST(Validate, NavStateRejectsFarAwayPosition) {
  nav_state_t m = good_nav();
  m.position[0] = 2.0 * MessageLimits::kMaxCoordinate;
  EXPECT_NE(validate(m), "");
}

TEST(Validate, NavStateRejectsNonFiniteVelocityAttitudeRates) {
  nav_state_t m = good_nav();
  m.velocity[1] = kNaNValue;
  EXPECT_NE(validate(m), "");
  m = good_nav();
  m.acceleration[2] = kInf;
  EXPECT_NE(validate(m), "");
  m = good_nav();
  m.euler[0] = kNaNValue;
  EXPECT_NE(validate(m), "");
  m = good_nav();
  m.body_rates[2] = kNaNValue;
  EXPECT_NE(validate(m), "");
  m = good_nav();
  m.quaternion[3] = kNaNValue;
  EXPECT_NE(validate(m), "");
}

TEST(Validate, NavStateRejectsOtherFrames) {
  nav_state_t m = good_nav();
  m.frame = "ENU";
  const std::string why = validate(m);
  EXPECT_NE(why, "");
  EXPECT_NE(why.find("ENU"), std::string::npos) << why;
  m.frame = "";
  EXPECT_NE(validate(m), "");
}

TEST(Validate, NavStateRejectsUnnormalisedQuaternion) {
  nav_state_t m = good_nav();
  m.quaternion[0] = 0.9;
  EXPECT_NE(validate(m), "");
  m.quaternion[0] = 0.0;  // all zero
  EXPECT_NE(validate(m), "");
  // A normalised, rotated quaternion passes.
  m.quaternion[0] = std::sqrt(0.5);
  m.quaternion[3] = std::sqrt(0.5);
  EXPECT_EQ(validate(m), "");
}

TEST(Validate, ActuatorCommandRejectsNaNAndImplausibleAngles) {
  actuator_cmd_t m = good_cmd();
  m.collective = kNaNValue;
  EXPECT_NE(validate(m), "");
  m = good_cmd();
  m.pedal = kInf;
  EXPECT_NE(validate(m), "");
  m = good_cmd();
  m.lon_cyclic = 2.0;
  EXPECT_NE(validate(m), "");
  m = good_cmd();
  m.lat_cyclic = -2.0;
  EXPECT_NE(validate(m), "");
}

TEST(Validate, MissionRejectsWaypointCountMismatch) {
  mission_t m = good_mission();
  m.num_waypoints = 3;
  EXPECT_NE(validate(m), "");
  m.num_waypoints = -1;
  EXPECT_NE(validate(m), "");
}

TEST(Validate, MissionRejectsZeroCaptureRadius) {
  mission_t m = good_mission();
  m.waypoints[1].capture_radius = 0.0;
  EXPECT_NE(validate(m), "");
  m.waypoints[1].capture_radius = kNaNValue;
  EXPECT_NE(validate(m), "");
}

TEST(Validate, MissionRejectsCruiseAboveMaxSpeed) {
  mission_t m = good_mission();
  m.cruise_speed = 3.5;
  EXPECT_NE(validate(m), "");
  m.cruise_speed = 0.0;
  EXPECT_NE(validate(m), "");
}

TEST(Validate, MissionRejectsBadLimitsAndWaypoints) {
  mission_t m = good_mission();
  m.limits.max_accel = 0.0;
  EXPECT_NE(validate(m), "");
  m = good_mission();
  m.limits.max_vertical_speed = kNaNValue;
  EXPECT_NE(validate(m), "");
  m = good_mission();
  m.waypoints[0].position[1] = kNaNValue;
  EXPECT_NE(validate(m), "");
  m = good_mission();
  m.frame = "ENU";
  EXPECT_NE(validate(m), "");
}

TEST(Validate, LidarScanRejectsArraysOfDifferentLength) {
  lidar_scan_t m = good_scan();
  m.elevation.pop_back();
  EXPECT_NE(validate(m), "");
  m = good_scan();
  m.status.push_back(lidar_scan_t::OK);
  EXPECT_NE(validate(m), "");
  m = good_scan();
  m.num_beams = 4;
  EXPECT_NE(validate(m), "");
}

TEST(Validate, LidarScanRejectsBadBeams) {
  lidar_scan_t m = good_scan();
  m.range[0] = std::numeric_limits<float>::quiet_NaN();  // an OK beam
  EXPECT_NE(validate(m), "");
  m = good_scan();
  m.status[1] = 7;
  EXPECT_NE(validate(m), "");
  m = good_scan();
  m.beam_dt_us[2] = -5;
  EXPECT_NE(validate(m), "");
  // A NaN range on a beam flagged as no-return is allowed.
  m = good_scan();
  m.range[1] = std::numeric_limits<float>::quiet_NaN();
  EXPECT_EQ(validate(m), "");
}

TEST(Validate, ScannerStatusCountsMustBeABeamCountAndAShareOfIt) {
  scanner_status_t m{};
  m.utime = 1'000'000;
  m.beams = 1364;
  m.returns = 1364;
  EXPECT_EQ(validate(m), "");
  m.returns = 0;
  EXPECT_EQ(validate(m), "");
  m.returns = 1365;
  EXPECT_NE(validate(m), "");
  m.returns = -1;
  EXPECT_NE(validate(m), "");
  m.returns = 0;
  m.beams = -1;
  EXPECT_NE(validate(m), "");
  m.beams = MessageLimits::kMaxBeams + 1;
  EXPECT_NE(validate(m), "");
}

TEST(Validate, ModesAndStatusesOutsideTheirConstantsAreRejected) {
  ref_traj_t m = good_traj();
  m.mode = ref_traj_t::LOOK_AROUND;
  EXPECT_EQ(validate(m), "");
  m.mode = ref_traj_t::LOOK_AROUND_LEFT + 1;
  EXPECT_NE(validate(m), "");
  m.mode = -1;
  EXPECT_NE(validate(m), "");
  global_path_t p = good_path();
  p.status = global_path_t::BACKTRACK;
  EXPECT_EQ(validate(p), "");
  p.status = global_path_t::BACKTRACK + 1;
  EXPECT_NE(validate(p), "");
}

TEST(Validate, NarrowPassagesNeedMatchingFiniteArrays) {
  narrow_passages_t m{};
  m.utime = 1000;
  m.frame = "NED";
  m.mission_id = 1;
  m.centre = {{60, 0, -30}};
  m.radius = {6.0};
  m.half_height = {3.0};
  m.num_passages = 1;
  EXPECT_EQ(validate(m), "");
  narrow_passages_t bad = m;
  bad.radius.clear();
  EXPECT_NE(validate(bad), "");
  bad = m;
  bad.centre[0][1] = std::numeric_limits<double>::infinity();
  EXPECT_NE(validate(bad), "");
  bad = m;
  bad.half_height[0] = 0.0;
  EXPECT_NE(validate(bad), "");
  bad = m;
  bad.num_passages = -1;
  EXPECT_NE(validate(bad), "");
  bad = m;
  bad.frame = "ENU";
  EXPECT_NE(validate(bad), "");
}

TEST(Validate, RefTrajRejectsNonIncreasingSampleTimes) {
  ref_traj_t m = good_traj();
  m.sample_time = {0.0, 0.5, 0.5};
  EXPECT_NE(validate(m), "");
  m.sample_time = {0.0, 1.0, 0.5};
  EXPECT_NE(validate(m), "");
}

TEST(Validate, RefTrajRejectsInconsistentSamples) {
  ref_traj_t m = good_traj();
  m.velocity.pop_back();
  EXPECT_NE(validate(m), "");
  m = good_traj();
  m.position[1][0] = kNaNValue;
  EXPECT_NE(validate(m), "");
  m = good_traj();
  m.num_samples = 2;
  EXPECT_NE(validate(m), "");
  m = good_traj();
  m.frame = "ENU";
  EXPECT_NE(validate(m), "");
}

TEST(Validate, ObstacleGridRejectsCellCountMismatch) {
  obstacle_grid_t m = good_grid();
  m.num_cells = 5;
  m.top_altitude.resize(5);
  EXPECT_NE(validate(m), "");
  m = good_grid();
  m.top_altitude.pop_back();  // num_cells says 6
  EXPECT_NE(validate(m), "");
  m = good_grid();
  m.rows = 0;
  m.num_cells = 0;
  m.top_altitude.clear();
  EXPECT_NE(validate(m), "");
}

TEST(Validate, OtherTypesRejectTheirBadCases) {
  sim_clock_t c = good_clock();
  c.real_time_factor = 0.0;
  EXPECT_NE(validate(c), "");

  virtual_obstacles_t o = good_obstacles();
  o.obstacles[0].height = -1;
  EXPECT_NE(validate(o), "");

  scan_world_t w = good_scan_world();
  w.num_points = 3;
  EXPECT_NE(validate(w), "");

  cuboid_list_t cl = good_cuboids();
  cl.cuboids[0].min_corner[0] = 70;  // above the max corner
  EXPECT_NE(validate(cl), "");

  global_path_t p = good_path();
  p.points[1][2] = kNaNValue;
  EXPECT_NE(validate(p), "");

  solver_stats_t s = good_stats();
  s.cost = kInf;
  EXPECT_NE(validate(s), "");
  // A map stamped after the status that names it: up to the 1 s the hosts'
  // clocks may differ by, accepted.
  s = good_stats();
  s.map_utime = s.utime + 1000000;
  EXPECT_EQ(validate(s), "");
  s.map_utime = s.utime + 1000001;
  EXPECT_NE(validate(s), "");

  control_status_t st = good_status();
  st.position_error[0] = kNaNValue;
  EXPECT_NE(validate(st), "");

  heartbeat_t h = good_heartbeat();
  h.service = "";
  EXPECT_NE(validate(h), "");

  // Per-channel counts: a name, and none negative or beyond the received.
  h = good_heartbeat();
  channel_counts_t input{};
  input.channel = "NAV_STATE";
  input.received = 10;
  input.lost = 3;
  input.duplicated = 1;
  input.unsequenced = 2;
  input.publishers = 1;
  h.inputs.push_back(input);
  h.num_inputs = 1;
  EXPECT_EQ(validate(h), "");
  h.inputs[0].lost = -1;
  EXPECT_NE(validate(h), "");
  h.inputs[0].lost = 3;
  h.inputs[0].unsequenced = 11;
  EXPECT_NE(validate(h), "");
  h.inputs[0].unsequenced = 2;
  h.inputs[0].channel = "";
  EXPECT_NE(validate(h), "");
}

// A scan point or a LIDAR range the size of FLT_MAX is finite, and sent
// the mapper and the RH optimiser walking beams 3.4e38 m long (the bus
// fuzz): scans lie within the world as every other position does.
TEST(Validate, ScansLieWithinTheWorld) {
  scan_world_t w = good_scan_world();
  w.points[0][0] = 2.0e6f;
  EXPECT_EQ(validate(w), "point not finite or out of range");
  w = good_scan_world();
  w.free_ray_ends.push_back({0.0f, std::numeric_limits<float>::max(), 0.0f});
  w.num_free_rays = static_cast<int32_t>(w.free_ray_ends.size());
  EXPECT_EQ(validate(w), "free ray end not finite or out of range");
  lidar_scan_t l = good_scan();
  l.max_range = 1.0e300;
  EXPECT_EQ(validate(l), "max range not positive or beyond the world");
}

// The RH optimiser pads a grid by its distance field's reach in cells: a
// cell of denorm_min metres made that pad the int of infinity (the bus
// fuzz). The resolution is the mapper's own range, the origin within the
// world.
TEST(Validate, ObstacleGridGeometryIsTheMappers) {
  for (double resolution : {0.05, 1.0, 20.0}) {
    obstacle_grid_t g = good_grid();
    g.resolution = resolution;
    EXPECT_EQ(validate(g), "") << resolution;
  }
  for (double resolution : {std::numeric_limits<double>::denorm_min(), 0.01, 21.0, 1e300}) {
    obstacle_grid_t g = good_grid();
    g.resolution = resolution;
    EXPECT_EQ(validate(g), "resolution outside 0.05..20 m") << resolution;
  }
  obstacle_grid_t g = good_grid();
  g.origin[1] = 2.0e6;
  EXPECT_EQ(validate(g), "grid origin or margin out of range");
  g = good_grid();
  g.safety_margin = -1.0;
  EXPECT_EQ(validate(g), "grid origin or margin out of range");
}

// Every float of every type is checked: the bus fuzz found these fields
// passed with NaN or Inf in them (tests/fuzz).
TEST(Validate, NonFiniteNumbersOutsideTheGeometryAreRejectedToo) {
  virtual_obstacles_t o = good_obstacles();
  o.obstacles[0].appear_time = kNaNValue;
  EXPECT_EQ(validate(o), "obstacle schedule not finite");
  o = good_obstacles();
  o.obstacles[0].disappear_time = kInf;
  EXPECT_EQ(validate(o), "obstacle schedule not finite");
  o = good_obstacles();
  o.obstacles[0].appear_time = -1.0;  // always there
  EXPECT_EQ(validate(o), "");

  cuboid_list_t cl = good_cuboids();
  cl.cuboids[0].confidence = kNaNValue;
  EXPECT_EQ(validate(cl), "cuboid confidence not finite");

  global_path_t p = good_path();
  p.cost = -kInf;
  EXPECT_EQ(validate(p), "path cost not finite");

  control_status_t st = good_status();
  st.yaw_reference = kNaNValue;
  EXPECT_EQ(validate(st), "status not finite");

  for (double heartbeat_t::*field : {&heartbeat_t::loop_time_mean, &heartbeat_t::loop_time_max,
                                     &heartbeat_t::cpu_fraction, &heartbeat_t::uptime}) {
    heartbeat_t h = good_heartbeat();
    h.*field = kInf;
    EXPECT_EQ(validate(h), "loop times, CPU or uptime not finite");
  }
}

}  // namespace
}  // namespace ofn
