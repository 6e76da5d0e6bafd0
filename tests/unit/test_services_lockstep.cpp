// The services together on the deterministic lockstep bus: a whole flight
// of the open course, and the controller with the simulated vehicle.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "ofn/actuator_cmd_t.hpp"
#include "ofn/common/braking.hpp"
#include "ofn/common/channels.hpp"
#include "ofn/common/config.hpp"
#include "ofn/common/logging.hpp"
#include "ofn/common/scenario.hpp"
#include "ofn/common/validate/actuator_cmd.hpp"
#include "ofn/common/validate/control_status.hpp"
#include "ofn/common/validate/mission.hpp"
#include "ofn/common/validate/nav_state.hpp"
#include "ofn/common/validate/ref_traj.hpp"
#include "ofn/common/validate/sim_clock.hpp"
#include "ofn/control_status_t.hpp"
#include "ofn/controller/controller_service.hpp"
#include "ofn/mission_uplink/mission_uplink_service.hpp"
#include "ofn/sensor_interface/sensor_interface_service.hpp"
#include "ofn/sim/lockstep.hpp"
#include "ofn/solver_stats_t.hpp"
#include "ofn/vehicle_sim/vehicle_sim_service.hpp"

namespace ofn {
namespace {

const std::string kOpenScenario = std::string(OFN_SOURCE_DIR) + "/sim/scenarios/open.yaml";

vehicle::VehicleSimConfig default_sim_config() {
  auto reader = YamlReader::empty("(defaults)");
  return vehicle::load_vehicle_sim_config(reader);
}

control::ControllerConfig default_controller_config() {
  auto reader = YamlReader::empty("(defaults)");
  return control::load_controller_config(reader);
}

struct FlightResult {
  bool arrived = false;
  Vec3 final_position = Vec3::Zero();
  double final_speed = 0;
  double max_speed_after_start = 0;  // m/s, true ground speed after the first 2 s
  double time = 0;
  int64_t messages = 0;
  int64_t controller_rejected = 0;
  int64_t sim_rejected = 0;
  std::vector<int8_t> modes;                              // distinct controller modes in order
  std::vector<std::pair<double, double>> yaw_references;  // t, rad (CONTROL_STATUS)
};

/// The planner's word as the controller's PerceptionWatch hears it: a
/// SOLVER_STATS "path clear" on a map of now, at 10 Hz, from `speaks_from`
/// until `silent_after` seconds (a dead optimiser, or a mapper that gets no
/// scans).
class PlannerStandIn {
 public:
  PlannerStandIn(sim::Lockstep& lockstep, double silent_after)
      : node_("planner_stand_in", lockstep.lcm(), lockstep.clock()), silent_after_(silent_after) {
    node_.add_timer(
        0.1, [this] { publish(); }, "status");
    // It clears the leg the controller flies, as the optimiser does.
    node_.subscribe<control_status_t>(channels::kControlStatus, [this](const control_status_t& m) {
      leg_ = {m.mission_id, m.active_waypoint};
    });
  }
  Node& node() { return node_; }
  double speaks_from = 0;

 private:
  void publish() {
    const Utime now = node_.now();
    if (to_seconds(now) < speaks_from || to_seconds(now) >= silent_after_) return;
    solver_stats_t s{};
    s.utime = now;
    s.status = solver_stats_t::NOT_RUN;
    s.message = "nominal guidance: path clear";
    s.map_utime = now;
    s.guidance_clear = true;
    s.mission_id = leg_.first;
    s.active_waypoint = leg_.second;
    node_.publish(channels::kSolverStats, s);
  }
  Node node_;
  double silent_after_;
  std::pair<int, int> leg_{-1, -1};  // mission id, waypoint
};

FlightResult fly_open_course(
    const Scenario& scenario, bool scanner = true,
    double planner_silent_after = std::numeric_limits<double>::infinity(),
    double time_limit = 150.0, const std::string& mission_path = kOpenScenario,
    const control::ControllerConfig& controller_config = default_controller_config()) {
  sim::Lockstep lockstep;
  auto sim_config = default_sim_config();
  sim_config.lidar.enabled = scanner;
  vehicle::VehicleSimService vehicle(lockstep.lcm(), lockstep.clock(), scenario, sim_config);
  // It tells the controller that the scanner scans (SCANNER_STATUS).
  auto sensor_reader = YamlReader::empty("(defaults)");
  sensing::SensorInterfaceService sensor(lockstep.lcm(), lockstep.clock(),
                                         sensing::load_sensor_interface_config(sensor_reader));
  uplink::MissionUplinkService uplink(lockstep.lcm(), lockstep.clock(), mission_path);
  control::ControllerService controller(lockstep.lcm(), lockstep.clock(), controller_config);
  lockstep.add(vehicle.node());
  lockstep.add(sensor.node());
  lockstep.add(uplink.node());
  lockstep.add(controller.node());
  PlannerStandIn planner(lockstep, planner_silent_after);
  lockstep.add(planner.node());
  FlightResult r;
  Node recorder("recorder", lockstep.lcm(), lockstep.clock());
  recorder.subscribe<control_status_t>(channels::kControlStatus, [&](const control_status_t& m) {
    r.yaw_references.emplace_back(to_seconds(m.utime), m.yaw_reference);
  });
  r.arrived = lockstep.run(to_utime(time_limit), [&] {
    if (r.modes.empty() || r.modes.back() != controller.mode())
      r.modes.push_back(controller.mode());
    if (to_seconds(lockstep.clock().now()) > 2.0)
      r.max_speed_after_start =
          std::max(r.max_speed_after_start, vehicle.model().state().velocity.norm());
    return controller.mode() == control_status_t::DONE;
  });
  r.final_position = vehicle.model().state().position;
  r.final_speed = vehicle.model().state().velocity.norm();
  r.time = to_seconds(lockstep.clock().now());
  r.messages = lockstep.messages();
  r.controller_rejected = controller.node().counters().rejected;
  r.sim_rejected = vehicle.node().counters().rejected;
  return r;
}

class LockstepServices : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { set_log_level("error"); }
  static void TearDownTestSuite() { set_log_level("info"); }
};

TEST_F(LockstepServices, OpenCourseFlightArrivesAtTheLastWaypoint) {
  const Scenario scenario = load_scenario(kOpenScenario);
  const FlightResult r = fly_open_course(scenario);
  ASSERT_TRUE(r.arrived) << "not DONE after " << r.time << " s; at "
                         << r.final_position.transpose();
  const Waypoint& last = scenario.waypoints.back();
  EXPECT_LE((r.final_position - last.position).norm(), last.capture_radius)
      << r.final_position.transpose();
  // 183 m at 3 m/s: it took about a minute, not the whole allowance.
  EXPECT_GT(r.time, 183.0 / scenario.limits.max_speed);
  EXPECT_LT(r.time, 120.0);
  // Flew the waypoints and then reported arrival.
  ASSERT_FALSE(r.modes.empty());
  EXPECT_EQ(r.modes.back(), control_status_t::DONE);
  EXPECT_NE(std::find(r.modes.begin(), r.modes.end(), control_status_t::WAYPOINT), r.modes.end());
  // Nobody rejected anything on a clean run.
  EXPECT_EQ(r.controller_rejected, 0);
  EXPECT_EQ(r.sim_rejected, 0);
}

// The windy test course (20 % heavy airframe, 15 kt crosswind, moderate
// turbulence): gusts carried the vehicle to 11.5 ft/s against the 10 ft/s
// limit while it flew at the limit. With the speed reserve the governor and
// the cruise keep room for them. The course starts at full speed in the
// gusts, before any has been measured, so the first 2 s are not judged here.
TEST_F(LockstepServices, InGustsTheSpeedReserveKeepsTheVehicleWithinItsLimit) {
  const std::string windy_path = std::string(OFN_SOURCE_DIR) + "/sim/scenarios/open_windy.yaml";
  const Scenario windy = load_scenario(windy_path);
  const double limit = windy.limits.max_speed;
  const FlightResult kept =
      fly_open_course(windy, true, std::numeric_limits<double>::infinity(), 200.0, windy_path);
  ASSERT_TRUE(kept.arrived) << "not DONE after " << kept.time << " s";
  EXPECT_LE(kept.max_speed_after_start, 1.02 * limit) << kept.max_speed_after_start / limit;
  EXPECT_EQ(kept.controller_rejected, 0);

  // Without it the same flight leaves the envelope: the test can tell.
  auto no_reserve = default_controller_config();
  no_reserve.speed_reserve.enabled = false;
  const FlightResult at_limit = fly_open_course(
      windy, true, std::numeric_limits<double>::infinity(), 200.0, windy_path, no_reserve);
  EXPECT_GT(at_limit.max_speed_after_start, 1.05 * limit) << at_limit.max_speed_after_start / limit;
}

TEST_F(LockstepServices, GuidanceStopsWhenThePlannersWordGoesStaleAndNeverStartsWithoutIt) {
  const Scenario scenario = load_scenario(kOpenScenario);
  // Confirmed until t = 30 s, then silent: the stop, then the hover.
  const FlightResult cut = fly_open_course(scenario, true, 30.0, 80.0);
  EXPECT_FALSE(cut.arrived);
  ASSERT_FALSE(cut.modes.empty());
  EXPECT_EQ(cut.modes.back(), control_status_t::SAFE_STOP);
  EXPECT_LT(cut.final_speed, 0.05);
  // Where the confirmed flight was at t = 30 s, plus the stop from cruise
  // (0.8 of the acceleration limit) and the second the watch waits.
  const FlightResult confirmed =
      fly_open_course(scenario, true, std::numeric_limits<double>::infinity(), 31.0);
  const double stopping = stop_from(Vec3::Zero(), Vec3(scenario.cruise_speed, 0, 0),
                                    0.8 * scenario.limits.max_accel, kStopRampTime, 0.0)
                              .distance();
  EXPECT_LT(cut.final_position.x(), confirmed.final_position.x() + stopping + 0.5);
  EXPECT_GT(cut.final_position.x(), confirmed.final_position.x() + 0.5 * stopping);

  // Never heard: the vehicle stops where the controller takes it over.
  const FlightResult never = fly_open_course(scenario, true, 0.0, 40.0);
  EXPECT_FALSE(never.arrived);
  EXPECT_LT(never.final_speed, 0.05);
  EXPECT_LT(never.final_position.x() - scenario.start_position.x(), stopping + 1.0);
}

/// Peak-to-peak yaw reference over a time window (rad).
double yaw_span(const FlightResult& r, double from, double to) {
  double lo = INFINITY, hi = -INFINITY;
  for (const auto& [t, yaw] : r.yaw_references)
    if (t >= from && t <= to) {
      lo = std::min(lo, yaw);
      hi = std::max(hi, yaw);
    }
  return hi - lo;
}

TEST_F(LockstepServices, YawSweepsTheScannerOnlyWhileScansArrive) {
  const Scenario scenario = load_scenario(kOpenScenario);
  const FlightResult scanning = fly_open_course(scenario, true);
  ASSERT_TRUE(scanning.arrived);
  // Faded in over the first period. At cruise the sweep reaches R_s beside
  // the path at the stopping distance (0.8 of the acceleration limit, the
  // stop without its onset): for the open course's limits wider than the
  // nominal 40 deg peak to peak.
  const double stopping = stop_from(Vec3::Zero(), Vec3(scenario.cruise_speed, 0, 0),
                                    0.8 * scenario.limits.max_accel, kStopRampTime, 0.0)
                              .distance();
  const double span = 2.0 * std::atan2(scenario.limits.clearance, stopping);
  ASSERT_GT(rad2deg(span), 41.0);
  EXPECT_NEAR(yaw_span(scanning, 10.0, 20.0), span, deg2rad(1.0));
  EXPECT_LT(rad2deg(yaw_span(scanning, 0.0, 1.0)), 10.0);
  const FlightResult blind = fly_open_course(scenario, false);
  ASSERT_TRUE(blind.arrived);
  EXPECT_LT(rad2deg(yaw_span(blind, 10.0, 15.0)), 1.0);
}

TEST_F(LockstepServices, SameScenarioGivesTheSameFlightBitForBit) {
  const Scenario scenario = load_scenario(kOpenScenario);
  const FlightResult a = fly_open_course(scenario);
  const FlightResult b = fly_open_course(scenario);
  EXPECT_EQ(a.arrived, b.arrived);
  EXPECT_EQ(a.time, b.time);
  EXPECT_EQ(a.messages, b.messages);
  EXPECT_EQ(a.final_position.x(), b.final_position.x());
  EXPECT_EQ(a.final_position.y(), b.final_position.y());
  EXPECT_EQ(a.final_position.z(), b.final_position.z());
}

/// Publishes a fixed navigation state at 100 Hz on the lockstep clock.
class NavFeeder {
 public:
  NavFeeder(sim::Lockstep& lockstep, Vec3 position)
      : node_("nav_feeder", lockstep.lcm(), lockstep.clock()), position_(position) {
    node_.add_timer(
        0.01, [this] { publish(); }, "nav");
  }
  Node& node() { return node_; }
  void move_to(const Vec3& position) { position_ = position; }
  bool enabled = true;
  Vec3 velocity = Vec3::Zero();  // reported only; the position stays

 private:
  void publish() {
    if (!enabled) return;
    nav_state_t m{};
    m.utime = node_.now();
    m.frame = "NED";
    for (int i = 0; i < 3; ++i) m.position[i] = position_[i];
    for (int i = 0; i < 3; ++i) m.velocity[i] = velocity[i];
    m.quaternion[0] = 1.0;
    node_.publish(channels::kNavState, m);
  }
  Node node_;
  Vec3 position_;
};

/// Records the controller's outputs.
class BusRecorder {
 public:
  explicit BusRecorder(sim::Lockstep& lockstep)
      : node_("recorder", lockstep.lcm(), lockstep.clock()) {
    node_.subscribe<actuator_cmd_t>(channels::kActuatorCmd,
                                    [this](const actuator_cmd_t& m) { commands.push_back(m); });
    node_.subscribe<control_status_t>(channels::kControlStatus,
                                      [this](const control_status_t& m) { status.push_back(m); });
  }
  Node& node() { return node_; }
  std::vector<actuator_cmd_t> commands;
  std::vector<control_status_t> status;

 private:
  Node node_;
};

// The planner's first word comes 2 s into the flight: the controller has
// the mission and flies its hold (a stop from the start speed), and the
// vehicle follows. Guidance then starts from where the vehicle is, not from
// where it was anchored when the mission came.
TEST_F(LockstepServices, GuidanceAfterTheHoldStartsOnTheVehicle) {
  const Scenario scenario = load_scenario(kOpenScenario);
  sim::Lockstep lockstep;
  vehicle::VehicleSimService vehicle(lockstep.lcm(), lockstep.clock(), scenario,
                                     default_sim_config());
  uplink::MissionUplinkService uplink(lockstep.lcm(), lockstep.clock(), kOpenScenario);
  control::ControllerService controller(lockstep.lcm(), lockstep.clock(),
                                        default_controller_config());
  PlannerStandIn planner(lockstep, std::numeric_limits<double>::infinity());
  planner.speaks_from = 2.0;
  BusRecorder recorder(lockstep);
  for (Node* n :
       {&vehicle.node(), &uplink.node(), &controller.node(), &planner.node(), &recorder.node()})
    lockstep.add(*n);
  lockstep.run(to_utime(4.0));

  bool held = false;
  int guided = 0;
  for (const auto& st : recorder.status) {
    if (st.mode == control_status_t::HOLD && st.mission_id >= 0) held = true;
    if (st.mode != control_status_t::WAYPOINT) continue;
    const double off =
        Vec3(st.position_error[0], st.position_error[1], st.position_error[2]).norm();
    EXPECT_LT(off, 0.1) << "at " << to_seconds(st.utime);
    ++guided;
  }
  EXPECT_TRUE(held);
  EXPECT_GE(guided, 50);
  // The vehicle flew the hold: it is past the start, and slower.
  EXPECT_GT(vehicle.model().state().position.x() - scenario.start_position.x(), 4.0);
}

TEST_F(LockstepServices, ControllerWithoutMissionHoldsPosition) {
  sim::Lockstep lockstep;
  const Vec3 here(12.0, -4.0, -25.0);
  NavFeeder feeder(lockstep, here);
  control::ControllerService controller(lockstep.lcm(), lockstep.clock(),
                                        default_controller_config());
  BusRecorder recorder(lockstep);
  lockstep.add(feeder.node());
  lockstep.add(controller.node());
  lockstep.add(recorder.node());
  lockstep.run(to_utime(2.0));

  EXPECT_EQ(controller.mode(), control_status_t::HOLD);
  ASSERT_FALSE(recorder.status.empty());
  const control_status_t& s = recorder.status.back();
  EXPECT_EQ(s.mode, control_status_t::HOLD);
  EXPECT_EQ(s.mission_id, -1);
  // Holding where it is: the reference is the vehicle's own position.
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(s.ref_position[i], here[i], 1e-9);
  // And it flies: commands at the control rate, finite and near hover.
  EXPECT_GE(recorder.commands.size(), 150u);
  const vehicle::RotorcraftParams p;
  const auto hover = vehicle::trim(vehicle::RotorcraftModel(p), Vec3::Zero(), 0.0).controls;
  for (const auto& c : recorder.commands) {
    ASSERT_EQ(validate(c), "");
    EXPECT_NEAR(c.collective, hover.collective, 0.02);
  }
  EXPECT_EQ(controller.node().counters().rejected, 0);
}

TEST_F(LockstepServices, ControllerWithoutNavigationNeverCommands) {
  sim::Lockstep lockstep;
  control::ControllerService controller(lockstep.lcm(), lockstep.clock(),
                                        default_controller_config());
  BusRecorder recorder(lockstep);
  lockstep.add(controller.node());
  lockstep.add(recorder.node());
  lockstep.run(to_utime(1.0));
  EXPECT_EQ(controller.mode(), control_status_t::NAV_STALE);
  EXPECT_TRUE(recorder.commands.empty());  // never fly blind from the ground
}

TEST_F(LockstepServices, ControllerCommandsLevelHoverWhenNavigationIsLost) {
  sim::Lockstep lockstep;
  NavFeeder feeder(lockstep, Vec3(0, 0, -30));
  control::ControllerService controller(lockstep.lcm(), lockstep.clock(),
                                        default_controller_config());
  BusRecorder recorder(lockstep);
  lockstep.add(feeder.node());
  lockstep.add(controller.node());
  lockstep.add(recorder.node());
  lockstep.run(to_utime(1.0));
  EXPECT_EQ(controller.mode(), control_status_t::HOLD);
  feeder.enabled = false;
  recorder.commands.clear();
  lockstep.run(to_utime(2.0));
  EXPECT_EQ(controller.mode(), control_status_t::NAV_STALE);
  ASSERT_FALSE(recorder.commands.empty());
  // Level hover: no cyclic.
  EXPECT_EQ(recorder.commands.back().lon_cyclic, 0.0);
  EXPECT_EQ(recorder.commands.back().lat_cyclic, 0.0);
}

/// Uplinks a mission (from `missions_from` seconds on) and, from `from`
/// seconds on, a fresh REF_TRAJ every 0.1 s: a straight line from the
/// vehicle at a constant velocity.
class TrajectoryFeeder {
 public:
  TrajectoryFeeder(sim::Lockstep& lockstep, mission_t mission, Vec3 position)
      : node_("trajectory_feeder", lockstep.lcm(), lockstep.clock()),
        mission_(std::move(mission)),
        position_(position) {
    node_.add_timer(
        0.1, [this] { publish(); }, "traj");
  }
  Node& node() { return node_; }
  void move_to(const Vec3& position) { position_ = position; }
  Vec3 velocity = Vec3::Zero();
  double from = 0;
  double missions_from = 0;
  int8_t mode = ref_traj_t::AVOIDANCE;

 private:
  void publish() {
    if (to_seconds(node_.now()) >= missions_from) node_.publish(channels::kMission, mission_);
    if (to_seconds(node_.now()) < from) return;
    ref_traj_t m{};
    m.utime = node_.now();
    m.t0_utime = m.utime;
    m.frame = "NED";
    m.mode = mode;
    m.num_samples = 2;
    m.sample_time = {0.0, 1.0};
    const Vec3 ahead = position_ + velocity;
    m.position = {{position_.x(), position_.y(), position_.z()}, {ahead.x(), ahead.y(), ahead.z()}};
    m.velocity = {{velocity.x(), velocity.y(), velocity.z()},
                  {velocity.x(), velocity.y(), velocity.z()}};
    m.acceleration = {{0, 0, 0}, {0, 0, 0}};
    node_.publish(channels::kRefTraj, m);
  }
  Node node_;
  mission_t mission_;
  Vec3 position_;
};

/// The controller alone on the bus at the start of the open course's first
/// leg: a navigation solution, trajectories from 1 s on, its status recorded.
/// The controller fed plans alone, with no planner status: waypoint
/// guidance before the first plan flies on (the PerceptionWatch is tested
/// by GuidanceStopsWhenThePlannersWordGoesStale...).
control::ControllerConfig without_watch(control::ControllerConfig config) {
  config.perception.enabled = false;
  return config;
}

struct ControllerFedTrajectories {
  explicit ControllerFedTrajectories(const control::ControllerConfig& config)
      : open(load_scenario(kOpenScenario)),
        nav(lockstep, open.waypoints.front().position),
        feeder(lockstep, uplink::mission_from_scenario(open, 1), open.waypoints.front().position),
        controller(lockstep.lcm(), lockstep.clock(), without_watch(config)),
        recorder(lockstep) {
    feeder.from = 1.0;
    for (Node* n : {&nav.node(), &feeder.node(), &controller.node(), &recorder.node()})
      lockstep.add(*n);
  }
  sim::Lockstep lockstep;
  Scenario open;
  NavFeeder nav;
  TrajectoryFeeder feeder;
  control::ControllerService controller;
  BusRecorder recorder;
};

TEST_F(LockstepServices, PathHeadingTurnsAtItsRateLimitAndHoldsWhenSlow) {
  // The vehicle faces north (the leg); from 1 s a trajectory heads east. The
  // heading speeds up over 0.5 s to turn at 30 deg/s, not in one step; a
  // slow reference then holds it wherever that reference points.
  const auto config = default_controller_config();
  ASSERT_NEAR(rad2deg(config.heading.max_rate), 30.0, 1e-9);
  ASSERT_NEAR(rad2deg(config.heading.max_accel), 60.0, 1e-9);
  ControllerFedTrajectories bus(config);
  bus.feeder.velocity = Vec3(0, 3, 0);
  // The vehicle moves as each trajectory starts, so the controller takes
  // them (a plan starting off both the reference and the vehicle is a jump).
  bus.nav.velocity = bus.feeder.velocity;
  bus.lockstep.run(to_utime(6.0));
  bus.feeder.velocity = Vec3(-0.5, -0.2, 0);  // slow, pointing elsewhere
  bus.nav.velocity = bus.feeder.velocity;
  bus.lockstep.run(to_utime(9.0));

  const auto yaw_at = [&](double t) {
    for (const auto& s : bus.recorder.status)
      if (to_seconds(s.utime) >= t) return rad2deg(s.yaw_reference);
    return std::numeric_limits<double>::quiet_NaN();
  };
  double turn_start = NAN;
  for (const auto& s : bus.recorder.status)
    if (s.mode == control_status_t::TRAJECTORY) {
      turn_start = to_seconds(s.utime);
      break;
    }
  ASSERT_TRUE(std::isfinite(turn_start));
  EXPECT_NEAR(yaw_at(turn_start - 0.1), 0.0, 1e-6);
  // 7.5 deg while speeding up over 0.5 s, then 30 deg/s.
  EXPECT_NEAR(yaw_at(turn_start + 1.0), 22.5, 1.5);
  EXPECT_NEAR(yaw_at(turn_start + 2.0), 52.5, 1.5);
  EXPECT_NEAR(yaw_at(5.5), 90.0, 1e-6);
  // Never faster than the limit between two status messages.
  for (size_t i = 1; i < bus.recorder.status.size(); ++i) {
    const double dt = to_seconds(bus.recorder.status[i].utime - bus.recorder.status[i - 1].utime);
    const double step =
        std::abs(bus.recorder.status[i].yaw_reference - bus.recorder.status[i - 1].yaw_reference);
    EXPECT_LE(step, config.heading.max_rate * dt + 1e-9) << "at " << i;
  }
  // Slow: the heading stays east.
  EXPECT_NEAR(yaw_at(8.9), 90.0, 1e-6);
}

TEST_F(LockstepServices, ALookAroundTurnsSteadilyThenPlansFlyAsTrajectories) {
  // From 1 s the optimiser asks for a look-around: a hover during which the
  // heading turns at its rate limit, fed forward. Then a plan at cruise
  // speed and a creeping one are flown as trajectories.
  const auto config = default_controller_config();
  ControllerFedTrajectories bus(config);
  bus.feeder.mode = ref_traj_t::LOOK_AROUND;
  bus.lockstep.run(to_utime(4.0));
  EXPECT_EQ(bus.controller.mode(), control_status_t::TRAJECTORY);
  // Turning at the limit: 30 deg/s between status messages, once turning.
  ASSERT_GE(bus.recorder.status.size(), 100u);
  double turned = 0;
  for (size_t i = 1; i < bus.recorder.status.size(); ++i) {
    if (to_seconds(bus.recorder.status[i - 1].utime) < 1.5) continue;
    const double dt = to_seconds(bus.recorder.status[i].utime - bus.recorder.status[i - 1].utime);
    const double step =
        wrap_angle(bus.recorder.status[i].yaw_reference - bus.recorder.status[i - 1].yaw_reference);
    EXPECT_NEAR(step, config.heading.max_rate * dt, 1e-9) << "at " << i;
    turned += step;
  }
  EXPECT_NEAR(rad2deg(turned), 30.0 * 2.5, 1.0);
  // A plan at cruise speed.
  bus.feeder.mode = ref_traj_t::AVOIDANCE;
  bus.feeder.velocity = bus.nav.velocity = Vec3(3, 0, 0);
  bus.lockstep.run(to_utime(4.5));
  EXPECT_EQ(bus.controller.mode(), control_status_t::TRAJECTORY);
  // Creeping, slower than the path heading's min_speed.
  bus.feeder.velocity = bus.nav.velocity = Vec3(0.5, 0, 0);
  bus.lockstep.run(to_utime(5.0));
  EXPECT_EQ(bus.controller.mode(), control_status_t::TRAJECTORY);
}

/// The rejections of `node` whose kind contains `text`.
int64_t rejected_with(const Node& node, const std::string& text) {
  int64_t n = 0;
  for (const auto& [kind, count] : node.counters().rejected_by_reason)
    if (kind.find(text) != std::string::npos) n += count;
  return n;
}

TEST_F(LockstepServices, AForgedPlanBeyondTheSpeedLimitIsNeverFlown) {
  // A stranger publishes a plan at 15 m/s (the mission allows 3.05): it
  // starts on the vehicle, so only the envelope can refuse it.
  sim::Lockstep lockstep;
  const Scenario open = load_scenario(kOpenScenario);
  const Vec3 here = open.waypoints.front().position;
  NavFeeder nav(lockstep, here);
  TrajectoryFeeder feeder(lockstep, uplink::mission_from_scenario(open, 1), here);
  feeder.from = 1.0;
  feeder.velocity = Vec3(15.0, 0, 0);
  nav.velocity = feeder.velocity;
  control::ControllerService controller(lockstep.lcm(), lockstep.clock(),
                                        default_controller_config());
  BusRecorder recorder(lockstep);
  for (Node* n : {&nav.node(), &feeder.node(), &controller.node(), &recorder.node()})
    lockstep.add(*n);
  lockstep.run(to_utime(3.0));
  EXPECT_GE(rejected_with(controller.node(), "plan refused: leaves the envelope"), 15);
  ASSERT_FALSE(recorder.status.empty());
  for (const auto& st : recorder.status) {
    ASSERT_NE(st.mode, control_status_t::TRAJECTORY) << "at " << to_seconds(st.utime);
    EXPECT_LE(std::hypot(st.ref_velocity[0], st.ref_velocity[1], st.ref_velocity[2]),
              1.02 * open.limits.max_speed);
  }
}

/// The controller's mode after 1 s of `mission` uplinked every 0.1 s over a
/// hovering vehicle at `here`, and its rejections whose kind contains `text`.
std::pair<int8_t, int64_t> fly_mission_only(const mission_t& mission, const Vec3& here,
                                            const std::string& text) {
  sim::Lockstep lockstep;
  NavFeeder nav(lockstep, here);
  TrajectoryFeeder feeder(lockstep, mission, here);
  feeder.from = 1e9;  // missions only
  control::ControllerService controller(lockstep.lcm(), lockstep.clock(),
                                        default_controller_config());
  for (Node* n : {&nav.node(), &feeder.node(), &controller.node()}) lockstep.add(*n);
  lockstep.run(to_utime(1.0));
  return {controller.mode(), rejected_with(controller.node(), text)};
}

// Navigation lost for 0.5 s (or the control loop stalled) while a plan is
// flown: the vehicle has flown on without commands, 15 m. The plan, and
// the plans still made along it, are not chased; the controller stops from
// the vehicle's state and takes only a plan that starts on the vehicle.
TEST_F(LockstepServices, AReferenceLapsedIsNotChased) {
  ControllerFedTrajectories bus(default_controller_config());
  bus.lockstep.run(to_utime(2.0));
  ASSERT_EQ(bus.controller.mode(), control_status_t::TRAJECTORY);
  const Vec3 plan_start = bus.open.waypoints.front().position;
  const Vec3 drifted = plan_start + Vec3(15, 0, 0);
  bus.nav.enabled = false;
  bus.lockstep.run(to_utime(2.5));
  ASSERT_EQ(bus.controller.mode(), control_status_t::NAV_STALE);
  bus.nav.move_to(drifted);
  bus.nav.enabled = true;
  bus.recorder.status.clear();
  bus.lockstep.run(to_utime(4.0));
  ASSERT_FALSE(bus.recorder.status.empty());
  int stopping = 0;
  for (const auto& st : bus.recorder.status) {
    if (st.mode == control_status_t::NAV_STALE) continue;
    EXPECT_EQ(st.mode, control_status_t::SAFE_STOP) << "at " << to_seconds(st.utime);
    EXPECT_LT((Vec3(st.ref_position[0], st.ref_position[1], st.ref_position[2]) - drifted).norm(),
              0.01)
        << "at " << to_seconds(st.utime);
    ++stopping;
  }
  EXPECT_GE(stopping, 50);
  EXPECT_GE(rejected_with(bus.controller.node(), "lapsed"), 1);
  EXPECT_GE(rejected_with(bus.controller.node(), "plan starts off"), 10);

  // A plan restarted at the vehicle is flown.
  bus.feeder.move_to(drifted);
  bus.lockstep.run(to_utime(4.5));
  EXPECT_EQ(bus.controller.mode(), control_status_t::TRAJECTORY);
}

TEST_F(LockstepServices, AMissionBeyondTheAirframeOrTheFenceIsRefused) {
  const Scenario open = load_scenario(kOpenScenario);
  const Vec3 here = open.waypoints.front().position;
  mission_t fast = uplink::mission_from_scenario(open, 1);
  fast.limits.max_speed = 30.0;  // the airframe's configured limit is 10 m/s
  const auto [fast_mode, fast_refusals] =
      fly_mission_only(fast, here, "mission refused: speed limit");
  EXPECT_EQ(fast_mode, control_status_t::HOLD);
  EXPECT_GE(fast_refusals, 5);

  // A waypoint 5 km away: outside the default geofence.
  mission_t far = uplink::mission_from_scenario(open, 1);
  far.waypoints.back().position[0] = 5000.0;
  const auto [far_mode, far_refusals] = fly_mission_only(far, here, "outside the geofence");
  EXPECT_EQ(far_mode, control_status_t::HOLD);
  EXPECT_GE(far_refusals, 5);
}

// A simulated vehicle is frozen at its start speed until the controller has
// a mission, while the hold flown before it moves on along its stop. When
// the mission came late (lost on a bad link), the flight began from where
// that reference had got to, metres ahead of the vehicle.
TEST_F(LockstepServices, ALateMissionBeginsWhereTheVehicleIs) {
  const Scenario open = load_scenario(kOpenScenario);
  const Vec3 here = open.waypoints.front().position;
  sim::Lockstep lockstep;
  NavFeeder nav(lockstep, here);
  nav.velocity = Vec3(3.048, 0, 0);  // frozen in trimmed flight
  TrajectoryFeeder feeder(lockstep, uplink::mission_from_scenario(open, 1), here);
  feeder.from = 1e9;  // no plans
  feeder.missions_from = 3.0;
  control::ControllerService controller(lockstep.lcm(), lockstep.clock(),
                                        default_controller_config());
  BusRecorder recorder(lockstep);
  for (Node* n : {&nav.node(), &feeder.node(), &controller.node(), &recorder.node()})
    lockstep.add(*n);

  lockstep.run(to_utime(2.9));
  ASSERT_FALSE(recorder.status.empty());
  const control_status_t before = recorder.status.back();
  EXPECT_EQ(before.mission_id, -1);
  // The hold's reference has moved on along its stop: the test's premise.
  EXPECT_GT(before.ref_position[0] - here.x(), 5.0);

  recorder.status.clear();
  lockstep.run(to_utime(3.3));
  ASSERT_FALSE(recorder.status.empty());
  int with_mission = 0;
  for (const auto& s : recorder.status) {
    if (s.mission_id != 1) continue;
    ++with_mission;
    // At most 0.3 s of flight at the start speed ahead, never behind.
    EXPECT_GT(s.ref_position[0] - here.x(), -0.01) << "at " << to_seconds(s.utime);
    EXPECT_LT(s.ref_position[0] - here.x(), 1.0) << "at " << to_seconds(s.utime);
  }
  EXPECT_GE(with_mission, 5);
}

// The simulated vehicle waits, frozen in trimmed flight at its start, for a
// controller with a mission; then it flies whatever mode that controller is
// in, a hold for the planner's first word included.
TEST_F(LockstepServices, VehicleSimIsReleasedByAControllerWithAMission) {
  sim::Lockstep lockstep;
  const Scenario open = load_scenario(kOpenScenario);
  vehicle::VehicleSimService vehicle(lockstep.lcm(), lockstep.clock(), open, default_sim_config());
  Node controller("controller", lockstep.lcm(), lockstep.clock());
  int32_t mission_id = -1;
  controller.add_timer(
      0.02,
      [&] {
        control_status_t s{};
        s.utime = controller.now();
        s.mode = control_status_t::HOLD;
        s.mission_id = mission_id;
        controller.publish(channels::kControlStatus, s);
      },
      "status");
  std::vector<nav_state_t> nav;
  controller.subscribe<nav_state_t>(channels::kNavState,
                                    [&](const nav_state_t& m) { nav.push_back(m); });
  lockstep.add(vehicle.node());
  lockstep.add(controller);
  lockstep.run(to_utime(1.0));
  ASSERT_GE(nav.size(), 90u);
  const Vec3 start = open.start_position;
  for (const auto& m : nav)
    EXPECT_NEAR(m.position[0], start.x(), 1e-9) << "held at " << to_seconds(m.utime);

  mission_id = 1;
  nav.clear();
  lockstep.run(to_utime(2.0));
  ASSERT_FALSE(nav.empty());
  // Trimmed at the start speed and commanded nothing else: it flies on.
  EXPECT_GT(nav.back().position[0] - start.x(), 0.5 * open.start_velocity.x());
}

// A vehicle_sim killed and restarted goes on with the same flight from its
// checkpoint: the clock from where it stopped, the aircraft where it was and
// as it moved. A new world at the course's start under services flying the
// old one made the fault suite's restart row jump 88.6 ft.
TEST_F(LockstepServices, ARestartedVehicleSimResumesTheFlightFromItsCheckpoint) {
  const Scenario open = load_scenario(kOpenScenario);
  auto config = default_sim_config();
  config.hold_until_engaged = false;  // flying from the start, on its trim
  sim::Lockstep first;
  vehicle::VehicleSimService original(first.lcm(), first.clock(), open, config);
  std::vector<vehicle::VehicleCheckpoint> saved;
  original.set_checkpoint_sink([&](const vehicle::VehicleCheckpoint& c) { saved.push_back(c); });
  first.add(original.node());
  first.run(to_utime(2.0));
  ASSERT_GE(saved.size(), 15u);  // every 0.1 s
  const vehicle::VehicleCheckpoint checkpoint = saved.back();
  EXPECT_GT(to_seconds(checkpoint.time_us), 1.8);
  EXPECT_TRUE(checkpoint.released);
  EXPECT_GT(checkpoint.state.position.x() - open.start_position.x(), 3.0);

  // The restart: its clock starts at the checkpoint's time.
  sim::Lockstep second;
  second.clock().set(checkpoint.time_us);
  vehicle::VehicleSimService restarted(second.lcm(), second.clock(), open, config, 1.0, checkpoint);
  Node listener("listener", second.lcm(), second.clock());
  std::vector<nav_state_t> nav;
  std::vector<sim_clock_t> ticks;
  listener.subscribe<nav_state_t>(channels::kNavState,
                                  [&](const nav_state_t& m) { nav.push_back(m); });
  listener.subscribe<sim_clock_t>(channels::kSimClock,
                                  [&](const sim_clock_t& m) { ticks.push_back(m); });
  second.add(restarted.node());
  second.add(listener);
  const Utime resumed_until = checkpoint.time_us + to_utime(1.0);
  second.run(resumed_until);
  ASSERT_GE(nav.size(), 90u);
  ASSERT_FALSE(ticks.empty());
  EXPECT_GE(ticks.front().utime, checkpoint.time_us);
  EXPECT_GE(ticks.front().step, checkpoint.steps);
  EXPECT_LT(nav.front().position[0] - checkpoint.state.position.x(), 0.1);
  EXPECT_GT(nav.front().position[0] - checkpoint.state.position.x(), -0.1);

  // And it flies on as the original does over the same second (the same
  // trim and no wind: the two agree to centimetres).
  first.run(resumed_until);
  const Vec3 original_at = original.model().state().position;
  const Vec3 restarted_at = restarted.model().state().position;
  EXPECT_LT((original_at - restarted_at).norm(), 0.05)
      << "original " << original_at.transpose() << ", restarted " << restarted_at.transpose();
}

TEST_F(LockstepServices, VehicleSimRefusesActuatorCommandsBeyondTheAirframesRange) {
  sim::Lockstep lockstep;
  const Scenario open = load_scenario(kOpenScenario);
  vehicle::VehicleSimService vehicle(lockstep.lcm(), lockstep.clock(), open, default_sim_config());
  Node stranger("stranger", lockstep.lcm(), lockstep.clock());
  stranger.add_timer(
      0.01,
      [&] {
        actuator_cmd_t c{};
        c.utime = stranger.now();
        c.collective = 0.1;
        c.lon_cyclic = 0.9;  // the airframe's cyclic ends at 0.16 rad
        stranger.publish(channels::kActuatorCmd, c);
      },
      "command");
  lockstep.add(vehicle.node());
  lockstep.add(stranger);
  lockstep.run(to_utime(1.0));
  EXPECT_GE(rejected_with(vehicle.node(), "longitudinal cyclic beyond its limits"), 90);
}

}  // namespace
}  // namespace ofn
