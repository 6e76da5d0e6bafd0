// The RH optimiser on the bus: nominal guidance while the way ahead is
// clear, avoidance trajectories as soon as a detected obstacle conflicts with
// it, a NOMINAL hand-back once clear again; bad input rejected and counted.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "ofn/common/channels.hpp"
#include "ofn/common/clock.hpp"
#include "ofn/common/logging.hpp"
#include "ofn/common/node.hpp"
#include "ofn/common/ref_traj_sample.hpp"
#include "ofn/common/validate.hpp"
#include "ofn/rh_optimizer/rh_optimizer_service.hpp"
#include "service_test_bus.hpp"

namespace ofn::rh {
namespace {

constexpr Utime kStart = 10 * kMicrosPerSecond;
constexpr double kAltitude = 36.576;  // m, 120 ft
constexpr double kSpeed = 3.048;      // m/s, 10 ft/s

mission_t mission() {
  return testing_support::course_mission(kStart);
}

nav_state_t nav(Utime t, const Vec3& position, const Vec3& velocity = Vec3(kSpeed, 0, 0)) {
  nav_state_t m{};
  m.utime = t;
  m.frame = "NED";
  for (int i = 0; i < 3; ++i) {
    m.position[i] = position[i];
    m.velocity[i] = velocity[i];
  }
  m.quaternion[0] = 1;
  return m;
}

/// A 40 m wide, 3 m thick wall `top` m tall with its near face at `north`,
/// in a grid around the vehicle; top = 0 gives an empty grid.
obstacle_grid_t grid(Utime t, double north, double top) {
  obstacle_grid_t m{};
  m.utime = t;
  m.frame = "NED";
  m.origin[0] = -20;
  m.origin[1] = -40;
  m.resolution = 1.0;
  m.safety_margin = 1.5;
  m.rows = 120;
  m.cols = 80;
  m.num_cells = m.rows * m.cols;
  m.top_altitude.assign(m.num_cells, 0.0f);
  if (top > 0)
    for (int r = 0; r < m.rows; ++r) {
      const double n = m.origin[0] + r + 0.5;
      if (n < north || n > north + 3) continue;
      for (int c = 20; c < 60; ++c) m.top_altitude[r * m.cols + c] = static_cast<float>(top);
    }
  return m;
}

/// The global planner's route over the wall (nodes at the clearance above
/// its top), every 2 m.
global_path_t route_over(Utime t) {
  const std::vector<Vec3> nodes = {Vec3(0, 0, -kAltitude), Vec3(38.9, 0, -48.8),
                                   Vec3(54.1, 0, -48.8), Vec3(152.4, 0, -kAltitude)};
  global_path_t m{};
  m.utime = t;
  m.frame = "NED";
  m.status = global_path_t::OK;
  for (size_t i = 1; i < nodes.size(); ++i) {
    const Vec3 d = nodes[i] - nodes[i - 1];
    const int n = static_cast<int>(std::ceil(d.norm() / 2.0));
    for (int k = 0; k < n; ++k) {
      const Vec3 p = nodes[i - 1] + d * (static_cast<double>(k) / n);
      m.points.push_back({p.x(), p.y(), p.z()});
    }
  }
  m.points.push_back({nodes.back().x(), nodes.back().y(), nodes.back().z()});
  m.num_points = static_cast<int32_t>(m.points.size());
  m.cost = 200;
  return m;
}

class RhOptimizerServiceTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { set_log_level("error"); }
  static void TearDownTestSuite() { set_log_level("info"); }

  RhOptimizerServiceTest()
      : bus_(kStart),
        service_(bus_.lcm(), bus_.clock(), config()),
        listener_("listener", bus_.lcm(), bus_.clock()) {
    listener_.subscribe<ref_traj_t>(channels::kRefTraj,
                                    [this](const ref_traj_t& m) { trajs_.push_back(m); });
    listener_.subscribe<solver_stats_t>(channels::kSolverStats,
                                        [this](const solver_stats_t& m) { stats_.push_back(m); });
  }
  static RhOptimizerServiceConfig config() {
    auto reader = YamlReader::empty("(defaults)");
    RhOptimizerServiceConfig c = load_rh_optimizer_config(reader);
    // No SCAN_WORLD is sent here, so every cell is unseen, and the ring of
    // unseen cells near the vehicle (on by default) would close the way
    // at once; these tests are of the grid's obstacles (the ring's own:
    // RhOptimizerServiceUnseen below).
    c.unseen_near_reach = 0.0;
    return c;
  }
  void deliver() { bus_.deliver(); }
  void advance_to(Utime t) { bus_.advance_to(service_.node(), t); }
  template <class Msg>
  void send(const std::string& channel, const Msg& m) {
    bus_.send(channel, m);
  }
  /// One 0.1 s step with fresh nav and grid just before the tick.
  void step(const Vec3& position, double wall_north, double wall_top,
            const Vec3& velocity = Vec3(kSpeed, 0, 0)) {
    const Utime t = bus_.now() + 50000;
    advance_to(t);
    send(channels::kNavState, nav(t, position, velocity));
    send(channels::kObstacleGrid, grid(t, wall_north, wall_top));
    advance_to(t + 50000);
  }

  testing_support::ServiceTestBus bus_;
  RhOptimizerService service_;
  Node listener_;
  std::vector<ref_traj_t> trajs_;
  std::vector<solver_stats_t> stats_;
};

TEST(RhOptimizerConfigReader, AnUnseenRingWhoseExemptDiscCoversItIsRefused) {
  const std::string path = testing::TempDir() + "rh_unseen_ring.yaml";
  auto load = [&](const std::string& text) {
    std::ofstream(path) << text;
    auto reader = YamlReader::load_file(path);
    return load_rh_optimizer_config(reader);
  };
  const auto good = load("unseen_near_reach: 10.0\nunseen_near_exempt: 4.0\n");
  EXPECT_DOUBLE_EQ(good.unseen_near_reach, 10.0);
  EXPECT_DOUBLE_EQ(good.unseen_near_exempt, 4.0);
  // Off, the exempt radius is not compared with anything.
  EXPECT_DOUBLE_EQ(load("unseen_near_reach: 0.0\nunseen_near_exempt: 8.0\n").unseen_near_exempt,
                   8.0);
  EXPECT_THROW(load("unseen_near_reach: 5.0\nunseen_near_exempt: 6.0\n"), ConfigError);
  EXPECT_THROW(load("unseen_near_reach: 5.0\nunseen_near_exempt: 5.0\n"), ConfigError);
  std::remove(path.c_str());
}

// The default config takes unseen cells 4-10 m from the vehicle as
// obstacle. With no scan ever received, nothing beside the vehicle has been
// seen: the open way ahead engages avoidance, and what is flown is a stop.
TEST(RhOptimizerServiceUnseen, WithNoScanTheUnseenSpaceBesideTheVehicleIsNotFlownThrough) {
  set_log_level("error");
  testing_support::ServiceTestBus bus(kStart);
  auto reader = YamlReader::empty("(defaults)");
  const RhOptimizerServiceConfig config = load_rh_optimizer_config(reader);
  ASSERT_GT(config.unseen_near_reach, 0.0);
  RhOptimizerService service(bus.lcm(), bus.clock(), config);
  Node listener("listener", bus.lcm(), bus.clock());
  std::vector<ref_traj_t> trajs;
  listener.subscribe<ref_traj_t>(channels::kRefTraj,
                                 [&](const ref_traj_t& m) { trajs.push_back(m); });
  bus.send(channels::kMission, mission());
  for (int i = 0; i < 5; ++i) {
    const Utime t = bus.now() + 50000;
    bus.advance_to(service.node(), t);
    bus.send(channels::kNavState,
             nav(t, Vec3(kSpeed * 0.1 * i, 0, -kAltitude), Vec3(kSpeed, 0, 0)));
    bus.send(channels::kObstacleGrid, grid(t, 0, 0));
    bus.advance_to(service.node(), t + 50000);
  }
  set_log_level("info");
  EXPECT_TRUE(service.engaged());
  ASSERT_FALSE(trajs.empty());
  EXPECT_EQ(trajs.back().mode, ref_traj_t::BRAKING);
}

TEST_F(RhOptimizerServiceTest, ClearWayAheadLeavesNominalGuidanceAlone) {
  send(channels::kMission, mission());
  for (int i = 0; i < 12; ++i) step(Vec3(kSpeed * 0.1 * i, 0, -kAltitude), 0, 0);
  EXPECT_FALSE(service_.engaged());
  // Only the hand-back's NOMINAL, repeated once a second while not engaged
  // (a controller holding a dead optimiser's stop learns it may resume).
  ASSERT_EQ(trajs_.size(), 1u);
  EXPECT_EQ(trajs_.front().mode, ref_traj_t::NOMINAL);
  ASSERT_FALSE(stats_.empty());
  EXPECT_EQ(stats_.back().status, solver_stats_t::NOT_RUN);
}

TEST_F(RhOptimizerServiceTest, TheControllersTrackingErrorWidensTheClearance) {
  send(channels::kMission, mission());
  // A wall whose top lies 7.5 m under the leg: clear of R_s (6.1 m) plus
  // the engage margin (0.5 m).
  const double top = kAltitude - 7.5;
  int i = 0;
  auto steps_with_error = [&](int steps, double error) {
    for (const int end = i + steps; i < end; ++i) {
      control_status_t status{};
      status.utime = bus_.now();
      status.mode = control_status_t::WAYPOINT;
      status.mission_id = mission().mission_id;
      status.active_waypoint = 1;
      status.position_error[1] = error;
      status.ref_traj_fresh = false;
      send(channels::kControlStatus, status);
      step(Vec3(kSpeed * 0.1 * i, 0, -kAltitude), 30, top);
    }
  };
  // Calm: a tenth of a metre off, nothing widens.
  steps_with_error(5, 0.1);
  ASSERT_FALSE(service_.engaged());
  // Gusts: the controller reports the vehicle 2.5 m off its reference, so
  // every clearance widens by 2.0 m (TrackingTube: less the 0.5 m onset).
  steps_with_error(5, 2.5);
  EXPECT_TRUE(service_.engaged());
}

TEST_F(RhOptimizerServiceTest, TheMissionsNarrowPassagesGoOutOnceASecond) {
  std::vector<narrow_passages_t> lists;
  listener_.subscribe<narrow_passages_t>(channels::kNarrowPassages,
                                         [&](const narrow_passages_t& m) { lists.push_back(m); });
  // Nothing before a mission: a list belongs to one.
  for (int i = 0; i < 12; ++i) step(Vec3(kSpeed * 0.1 * i, 0, -kAltitude), 0, 0);
  EXPECT_TRUE(lists.empty());
  send(channels::kMission, mission());
  for (int i = 12; i < 34; ++i) step(Vec3(kSpeed * 0.1 * i, 0, -kAltitude), 0, 0);
  // The whole (here empty) list, tagged with the mission, once a second.
  ASSERT_GE(lists.size(), 2u);
  ASSERT_LE(lists.size(), 3u);
  for (const auto& m : lists) {
    EXPECT_EQ(m.mission_id, mission().mission_id);
    EXPECT_EQ(m.num_passages, 0);
    EXPECT_EQ(validate(m), "");
  }
}

TEST_F(RhOptimizerServiceTest, AWallAheadEngagesAvoidanceOverIt) {
  send(channels::kMission, mission());
  send(channels::kGlobalPath, route_over(bus_.now()));
  for (int i = 0; i < 5; ++i) step(Vec3(0, 0, -kAltitude), 45.0, 42.7);
  ASSERT_TRUE(service_.engaged());
  ASSERT_FALSE(trajs_.empty());
  ref_traj_t t = trajs_.back();
  EXPECT_EQ(t.mode, ref_traj_t::AVOIDANCE);
  // Sent as its B-spline alone (one datagram); sampled as receivers do.
  EXPECT_EQ(t.num_samples, 0);
  EXPECT_GT(t.num_control_points, 0);
  EXPECT_LT(t.getEncodedSize(), 1400);
  expand_ref_traj(t);
  EXPECT_GE(t.num_samples, 2);
  // It starts on the last plan (the vehicle, held still here, is within
  // replan_position_error of it) and climbs above the wall top plus the
  // clearance by the time it is over the wall.
  EXPECT_NEAR(t.position.front()[0], 0.0, 3.0);
  double altitude_over_wall = 0;
  for (size_t i = 0; i < t.position.size(); ++i)
    if (t.position[i][0] >= 45.0 && t.position[i][0] <= 48.0)
      altitude_over_wall = std::max(altitude_over_wall, -t.position[i][2]);
  EXPECT_GE(altitude_over_wall, 42.7 + 6.096);
  ASSERT_FALSE(stats_.empty());
  EXPECT_EQ(stats_.back().status, solver_stats_t::SOLVED);
  EXPECT_GT(stats_.back().iterations, 0);
}

// A stop is held against a gust: a vehicle pushed off it (4 m aside and
// 2 m/s faster towards the wall, past both replan errors of a moving plan)
// gets the same stop again, to be flown back to, not a new one starting
// with the gust's velocity.
TEST_F(RhOptimizerServiceTest, AGustDoesNotMoveAStop) {
  send(channels::kMission, mission());
  // A wall too tall to climb 13 m ahead at cruise speed: nothing to solve
  // but a stop.
  step(Vec3(0, 0, -kAltitude), 13.0, 300.0);
  ASSERT_TRUE(service_.engaged());
  ASSERT_FALSE(trajs_.empty());
  ASSERT_EQ(trajs_.back().mode, ref_traj_t::BRAKING);
  // The vehicle flies the stop for a few steps.
  for (int i = 0; i < 3; ++i) {
    ref_traj_t flown = trajs_.back();
    expand_ref_traj(flown);
    const auto now = sample_ref_traj_at(flown, to_seconds(bus_.now() + 50000 - flown.t0_utime));
    ASSERT_TRUE(now.has_value());
    step(now->position, 13.0, 300.0, now->velocity);
  }
  ref_traj_t stop = trajs_.back();
  expand_ref_traj(stop);
  const size_t published = trajs_.size();
  const Utime gust_time = bus_.now() + 50000;
  const auto held = sample_ref_traj_at(stop, to_seconds(gust_time - stop.t0_utime));
  ASSERT_TRUE(held.has_value());
  const Vec3 pushed = held->position + Vec3(0, 4.0, 0);
  const Vec3 gusted = held->velocity + Vec3(2.0, 0, 0);
  step(pushed, 13.0, 300.0, gusted);
  ASSERT_GT(trajs_.size(), published);
  ref_traj_t next = trajs_.back();
  expand_ref_traj(next);
  // It starts where the stop is at its start time.
  const auto start = sample_ref_traj_at(next, 0.0);
  const auto on_stop = sample_ref_traj_at(stop, to_seconds(next.t0_utime - stop.t0_utime));
  ASSERT_TRUE(start.has_value() && on_stop.has_value());
  EXPECT_LT((start->position - on_stop->position).norm(), 0.01);
  EXPECT_LT((start->velocity - on_stop->velocity).norm(), 0.01);
  EXPECT_GT((start->position - pushed).norm(), 3.5);
  EXPECT_GT((start->velocity - gusted).norm(), 1.5);
}

TEST_F(RhOptimizerServiceTest, HandsBackWithANominalTrajectoryOnceClearAndOnTheLeg) {
  send(channels::kMission, mission());
  for (int i = 0; i < 3; ++i) step(Vec3(0, 0, -kAltitude), 45.0, 42.7);
  ASSERT_TRUE(service_.engaged());
  // The wall is gone and the vehicle is on the leg: after the hold, back.
  for (int i = 0; i < 20 && service_.engaged(); ++i) step(Vec3(1.0 + 0.3 * i, 0, -kAltitude), 0, 0);
  EXPECT_FALSE(service_.engaged());
  ASSERT_FALSE(trajs_.empty());
  EXPECT_EQ(trajs_.back().mode, ref_traj_t::NOMINAL);
}

TEST_F(RhOptimizerServiceTest, BadInputIsRejectedCountedAndSurvived) {
  send(channels::kMission, mission());
  step(Vec3(0, 0, -kAltitude), 45.0, 42.7);
  const int64_t before = service_.node().counters().rejected;
  obstacle_grid_t nan_grid = grid(bus_.now(), 45.0, 42.7);
  nan_grid.top_altitude[5] = std::numeric_limits<float>::quiet_NaN();
  send(channels::kObstacleGrid, nan_grid);
  obstacle_grid_t wrong = grid(bus_.now(), 45.0, 42.7);
  wrong.rows = 7;  // rows * cols != cells
  wrong.num_cells = 7 * wrong.cols;
  wrong.top_altitude.resize(wrong.num_cells);
  wrong.rows = 8;
  send(channels::kObstacleGrid, wrong);
  send(channels::kNavState, nav(bus_.now(), Vec3(std::nan(""), 0, 0)));
  global_path_t path{};
  path.utime = bus_.now();
  path.frame = "ENU";
  send(channels::kGlobalPath, path);
  EXPECT_GE(service_.node().counters().rejected - before, 4);
  // Still working.
  for (int i = 0; i < 3; ++i) step(Vec3(0, 0, -kAltitude), 45.0, 42.7);
  EXPECT_TRUE(service_.engaged());
  ASSERT_FALSE(trajs_.empty());
  for (const auto& t : trajs_)
    for (const auto& p : t.position)
      for (double v : p) EXPECT_TRUE(std::isfinite(v));
}

}  // namespace
}  // namespace ofn::rh
