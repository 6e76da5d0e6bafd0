// The global planner on the bus: a route from MISSION, NAV_STATE and CUBOIDS,
// republished once a second and at once when the cuboids change; bad input
// is rejected and counted, and the service keeps running.

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "config_files.hpp"
#include "ofn/common/channels.hpp"
#include "ofn/common/clock.hpp"
#include "ofn/common/config.hpp"
#include "ofn/common/logging.hpp"
#include "ofn/common/node.hpp"
#include "ofn/common/validate/global_path.hpp"
#include "ofn/control_status_t.hpp"
#include "ofn/global_planner/global_planner_service.hpp"
#include "service_test_bus.hpp"

namespace ofn::planning {
namespace {

constexpr Utime kStart = 10 * kMicrosPerSecond;
constexpr double kAltitude = 36.576;  // m, 120 ft

mission_t mission() {
  return testing_support::course_mission(kStart);
}

nav_state_t nav(Utime t, double north) {
  nav_state_t m{};
  m.utime = t;
  m.frame = "NED";
  m.position[0] = north;
  m.position[2] = -kAltitude;
  m.velocity[0] = 3.048;
  m.quaternion[0] = 1;
  return m;
}

/// bench1's wall: 10 ft thick, 300 ft wide, 140 ft tall, at 200 ft.
cuboid_list_t wall(Utime t, bool top_observed = true) {
  cuboid_list_t m{};
  m.utime = t;
  m.frame = "NED";
  cuboid_t c{};
  c.id = 7;
  c.min_corner[0] = 59.4;
  c.max_corner[0] = 62.5;
  c.min_corner[1] = -45.7;
  c.max_corner[1] = 45.7;
  c.min_corner[2] = -42.7;
  c.max_corner[2] = 0.0;
  c.top_observed = top_observed;
  c.confidence = 1;
  c.last_seen_utime = t;
  m.cuboids.push_back(c);
  m.num_cuboids = 1;
  return m;
}

class GlobalPlannerServiceTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { set_log_level("error"); }
  static void TearDownTestSuite() { set_log_level("info"); }

  GlobalPlannerServiceTest()
      : bus_(kStart),
        service_(bus_.lcm(), bus_.clock(), config()),
        listener_("listener", bus_.lcm(), bus_.clock()) {
    listener_.subscribe<global_path_t>(channels::kGlobalPath,
                                       [this](const global_path_t& m) { paths_.push_back(m); });
  }
  static GlobalPlannerServiceConfig config() {
    auto reader = YamlReader::empty("(defaults)");
    return load_global_planner_config(reader);
  }
  void deliver() { bus_.deliver(); }
  void advance_to(Utime t) { bus_.advance_to(service_.node(), t); }
  template <class Msg>
  void send(const std::string& channel, const Msg& m) {
    bus_.send(channel, m);
  }
  static double highest_altitude(const global_path_t& p) {
    double h = -std::numeric_limits<double>::infinity();
    for (const auto& q : p.points) h = std::max(h, -q[2]);
    return h;
  }

  testing_support::ServiceTestBus bus_;
  GlobalPlannerService service_;
  Node listener_;
  std::vector<global_path_t> paths_;
};

TEST_F(GlobalPlannerServiceTest, NoRouteUntilMissionNavAndCuboidsAreKnown) {
  send(channels::kMission, mission());
  send(channels::kNavState, nav(kStart, 0));
  advance_to(kStart + 3 * kMicrosPerSecond);
  EXPECT_TRUE(paths_.empty());
  send(channels::kNavState, nav(bus_.now(), 0));
  send(channels::kCuboids, wall(bus_.now()));
  ASSERT_FALSE(paths_.empty());
}

TEST_F(GlobalPlannerServiceTest, GoesOverTheWallAndReplansOnChange) {
  send(channels::kMission, mission());
  send(channels::kNavState, nav(kStart, 0));
  send(channels::kCuboids, wall(kStart));
  ASSERT_EQ(paths_.size(), 1u);
  const global_path_t& first = paths_.back();
  EXPECT_EQ(first.status, global_path_t::OK);
  EXPECT_GT(first.cost, 152.4);
  // Over the 42.7 m wall with 6.1 m clearance.
  EXPECT_GE(highest_altitude(first), 42.7 + 6.096 - 0.1);
  EXPECT_NEAR(first.points.front()[0], 0.0, 1e-9);
  EXPECT_NEAR(first.points.back()[0], 152.4, 1e-9);

  // Periodic replanning once a second (the first timer tick comes at once).
  const size_t before = paths_.size();
  for (int i = 1; i <= 3; ++i) {
    const Utime t = kStart + i * kMicrosPerSecond - 100000;
    advance_to(t);
    send(channels::kNavState, nav(t, 3.0 * i));
    send(channels::kCuboids, wall(t));  // the same set: no extra plan
    advance_to(t + 200000);
  }
  EXPECT_GE(paths_.size() - before, 3u);
  EXPECT_LE(paths_.size() - before, 4u);
  // A narrower obstacle whose top was never seen (it reaches the ceiling):
  // the route goes round.
  const Utime t = bus_.now();
  const size_t published = paths_.size();
  send(channels::kNavState, nav(t, 0.0));
  cuboid_list_t tower = wall(t, false);
  tower.cuboids[0].min_corner[1] = -10;
  tower.cuboids[0].max_corner[1] = 10;
  send(channels::kCuboids, tower);
  ASSERT_EQ(paths_.size(), published + 1);
  EXPECT_EQ(paths_.back().status, global_path_t::OK);
  EXPECT_LT(highest_altitude(paths_.back()), kAltitude + 1.0);
}

TEST_F(GlobalPlannerServiceTest, StartInsideAnObstacleIsReportedNotFatal) {
  send(channels::kMission, mission());
  send(channels::kNavState, nav(kStart, 61.0));  // inside the wall
  send(channels::kCuboids, wall(kStart));
  ASSERT_FALSE(paths_.empty());
  EXPECT_EQ(paths_.back().status, global_path_t::START_INSIDE_OBSTACLE);
  EXPECT_EQ(paths_.back().num_points, 0);
}

TEST_F(GlobalPlannerServiceTest, BadCuboidsAreRejectedAndCounted) {
  send(channels::kMission, mission());
  send(channels::kNavState, nav(kStart, 0));
  cuboid_list_t bad = wall(kStart);
  bad.cuboids[0].min_corner[1] = std::numeric_limits<double>::quiet_NaN();
  send(channels::kCuboids, bad);
  cuboid_list_t inverted = wall(kStart);
  std::swap(inverted.cuboids[0].min_corner[0], inverted.cuboids[0].max_corner[0]);
  send(channels::kCuboids, inverted);
  const std::vector<uint8_t> junk(37, 0xAB);
  bus_.lcm().publish(channels::kCuboids, junk.data(), static_cast<unsigned>(junk.size()));
  deliver();
  EXPECT_TRUE(paths_.empty());
  EXPECT_GE(service_.node().counters().rejected, 3);
  // Still alive: a good set plans.
  send(channels::kCuboids, wall(kStart));
  ASSERT_EQ(paths_.size(), 1u);
  EXPECT_EQ(paths_.back().status, global_path_t::OK);
}

narrow_passages_t passages(Utime t, int32_t mission_id, double east) {
  narrow_passages_t m{};
  m.utime = t;
  m.frame = "NED";
  m.mission_id = mission_id;
  m.centre = {{61.0, east, -(42.7 + 6.096)}};
  m.radius = {10.0};
  m.half_height = {3.0};
  m.num_passages = 1;
  return m;
}

TEST_F(GlobalPlannerServiceTest, ThePassagesOfThisMissionAreRoutedRound) {
  const mission_t plan = mission();
  send(channels::kMission, plan);
  send(channels::kNavState, nav(kStart, 0));
  send(channels::kCuboids, wall(kStart));
  ASSERT_EQ(paths_.size(), 1u);
  ASSERT_GE(highest_altitude(paths_.back()), 42.7 + 6.096 - 0.1);  // over the wall's middle
  // Another mission's passages say nothing about this one.
  send(channels::kNarrowPassages, passages(kStart, plan.mission_id + 1, 0.0));
  EXPECT_EQ(paths_.size(), 1u);
  // The way over the wall's middle is too narrow: the route goes another
  // way at once (round an end; too sharp for Eq. 10 from here, so it comes
  // as the geometric guess with NO_PATH).
  send(channels::kNarrowPassages, passages(kStart, plan.mission_id, 0.0));
  ASSERT_EQ(paths_.size(), 2u);
  ASSERT_GE(paths_.back().points.size(), 2u);
  for (const auto& q : paths_.back().points)
    if (std::abs(-q[2] - (42.7 + 6.096)) <= 3.0) {
      EXPECT_GE(std::hypot(q[0] - 61.0, q[1]), 10.0 - 0.1);
    }
  // The same list again: no extra plan. A list with a non-finite centre is
  // rejected and counted.
  send(channels::kNarrowPassages, passages(kStart, plan.mission_id, 0.0));
  EXPECT_EQ(paths_.size(), 2u);
  const int64_t rejected = service_.node().counters().rejected;
  send(channels::kNarrowPassages,
       passages(kStart, plan.mission_id, std::numeric_limits<double>::quiet_NaN()));
  EXPECT_EQ(service_.node().counters().rejected, rejected + 1);
  EXPECT_EQ(paths_.size(), 2u);
}

TEST_F(GlobalPlannerServiceTest, AnOutAndBackRouteFollowsTheControllersLeg) {
  // Out to 152.4 m and back to the start over the same line: from the
  // vehicle's position the two legs cannot be told apart.
  mission_t out_and_back = mission();
  out_and_back.waypoints.push_back(out_and_back.waypoints.front());
  out_and_back.num_waypoints = 3;
  send(channels::kMission, out_and_back);
  send(channels::kNavState, nav(kStart, 60.0));
  cuboid_list_t no_cuboids{};
  no_cuboids.utime = kStart;
  no_cuboids.frame = "NED";
  send(channels::kCuboids, no_cuboids);
  ASSERT_FALSE(paths_.empty());
  EXPECT_NEAR(paths_.back().points.back()[0], 152.4, 1e-9);  // outwards first

  // The controller's word for another mission is no word.
  control_status_t status{};
  status.utime = bus_.now();
  status.mission_id = out_and_back.mission_id + 1;
  status.active_waypoint = 2;
  send(channels::kControlStatus, status);
  send(channels::kNavState, nav(bus_.now(), 60.0));
  EXPECT_NEAR(paths_.back().points.back()[0], 152.4, 1e-9);

  // This mission's: the way back.
  status.mission_id = out_and_back.mission_id;
  send(channels::kControlStatus, status);
  const size_t before = paths_.size();
  send(channels::kNavState, nav(bus_.now(), 60.0));
  ASSERT_GT(paths_.size(), before);
  EXPECT_NEAR(paths_.back().points.back()[0], -30.48, 1e-9);

  // And never back out again.
  status.active_waypoint = 1;
  send(channels::kControlStatus, status);
  send(channels::kNavState, nav(bus_.now(), 60.0));
  advance_to(bus_.now() + 2 * kMicrosPerSecond);
  EXPECT_NEAR(paths_.back().points.back()[0], -30.48, 1e-9);
}

using testing_support::ConfigFiles;

TEST_F(ConfigFiles, TheTimeCostIsOffByDefaultAndTakesTheMissionsVerticalSpeed) {
  // Off: a segment costs its length (the paper's Eq. 9), whatever the mission.
  mission_t m = mission();
  m.limits.max_vertical_speed = 1.524;
  auto defaults = YamlReader::empty("(defaults)");
  const GlobalPlannerServiceConfig off = load_global_planner_config(defaults);
  EXPECT_FALSE(off.time_cost);
  EXPECT_EQ(planner_config_for(off, m).vertical_speed, 0.0);
  // On: the mission's vertical speed limit bounds the climbs' time.
  auto on_file = YamlReader::load_file(write("global_planner.yaml", "time_cost: true\n"));
  const GlobalPlannerServiceConfig on = load_global_planner_config(on_file);
  EXPECT_TRUE(on.time_cost);
  EXPECT_DOUBLE_EQ(planner_config_for(on, m).vertical_speed, 1.524);
  // Not a boolean: an error naming the file and the field.
  const std::string bad = write("bad.yaml", "time_cost: 3\n");
  auto bad_file = YamlReader::load_file(bad);
  try {
    load_global_planner_config(bad_file);
    FAIL() << "loaded";
  } catch (const ConfigError& e) {
    EXPECT_NAMES(std::string(e.what()), bad, "time_cost");
  }
}

}  // namespace
}  // namespace ofn::planning
