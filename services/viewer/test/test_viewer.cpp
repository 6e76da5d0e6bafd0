// The viewer's core: what the snapshot says, what it refuses, how the trail
// is bounded, and the snapshot hub's hand-over between threads.

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <limits>
#include <thread>

#include "ofn/common/braking.hpp"
#include "ofn/common/node.hpp"
#include "ofn/viewer/snapshot_hub.hpp"
#include "ofn/viewer/view_state.hpp"

namespace ofn::viewer {
namespace {

nav_state_t nav(double t, double north, double east = 0, double down = -10) {
  nav_state_t m{};
  m.utime = to_utime(t);
  m.frame = "NED";
  m.position[0] = north;
  m.position[1] = east;
  m.position[2] = down;
  m.velocity[0] = 3.0;
  m.velocity[1] = 4.0;
  m.quaternion[0] = 1.0;
  return m;
}

mission_t mission() {
  mission_t m{};
  m.utime = 0;
  m.mission_id = 1;
  m.name = "test course";
  m.frame = "NED";
  m.cruise_speed = 3;
  m.limits.max_speed = 3;
  m.limits.max_accel = 1;
  m.limits.max_vertical_speed = 1;
  m.limits.clearance = 5;
  m.limits.sensor_range = 30;
  waypoint_t w{};
  w.position[0] = 100;
  w.position[2] = -10;
  w.capture_radius = 2;
  m.waypoints.push_back(w);
  m.num_waypoints = 1;
  return m;
}

// A straight plan north at 2 m/s from `north`, stamped at t.
ref_traj_t plan(double t, double north) {
  ref_traj_t m{};
  m.utime = to_utime(t);
  m.t0_utime = to_utime(t);
  m.frame = "NED";
  m.mode = ref_traj_t::AVOIDANCE;
  for (int i = 0; i <= 20; ++i) {
    const double s = 0.25 * i;
    m.sample_time.push_back(s);
    m.position.push_back({north + 2.0 * s, 0.0, -10.0});
    m.velocity.push_back({2.0, 0.0, 0.0});
    m.acceleration.push_back({0.0, 0.0, 0.0});
  }
  m.num_samples = static_cast<int32_t>(m.sample_time.size());
  return m;
}

virtual_obstacles_t one_box(double north, double east) {
  virtual_obstacles_t m{};
  m.utime = 0;
  m.revision = 1;
  m.ground_altitude = 0;
  obstacle_t o{};
  o.id = 7;
  o.kind = obstacle_t::BOX;
  o.center[0] = north;
  o.center[1] = east;
  o.size[0] = 4;
  o.size[1] = 4;
  o.height = 30;
  o.appear_time = -1;
  o.disappear_time = -1;
  m.obstacles.push_back(o);
  m.num_obstacles = 1;
  return m;
}

TEST(ViewState, SnapshotCarriesVehicleStatusPlanAndStop) {
  ViewState view;
  EXPECT_EQ(view.on_mission(mission()), "");
  EXPECT_EQ(view.on_nav_state(nav(1.0, 10.0)), "");
  control_status_t status{};
  status.utime = to_utime(1.0);
  status.mode = control_status_t::TRAJECTORY;
  status.ref_traj_fresh = true;
  EXPECT_EQ(view.on_control_status(status), "");
  solver_stats_t solver{};
  solver.utime = to_utime(1.0);
  solver.status = solver_stats_t::SOLVED;
  solver.message = "solved";
  solver.iterations = 12;
  solver.solve_time = 0.02;
  EXPECT_EQ(view.on_solver_stats(solver), "");
  EXPECT_EQ(view.on_ref_traj(plan(1.0, 10.0)), "");

  const auto s = view.snapshot();
  EXPECT_EQ(s["display_unit"], "ft");
  EXPECT_DOUBLE_EQ(s["vehicle"]["position"][0].get<double>(), 10.0);
  EXPECT_DOUBLE_EQ(s["vehicle"]["speed"].get<double>(), 5.0);
  EXPECT_DOUBLE_EQ(s["vehicle"]["altitude"].get<double>(), 10.0);
  EXPECT_TRUE(s["vehicle"]["clearance"].is_null());  // no VIRTUAL_OBSTACLES yet
  EXPECT_EQ(s["control"]["mode"], "TRAJECTORY");
  EXPECT_EQ(s["solver"]["status"], "SOLVED");
  EXPECT_EQ(s["solver"]["iterations"], 12);
  EXPECT_EQ(s["ref_traj"]["mode"], "AVOIDANCE");
  EXPECT_EQ(s["ref_traj"]["positions"].size(), 21u);
  EXPECT_EQ(s["mission"]["name"], "test course");
  // The stop starts where the plan is 0.5 s after its stamp (north 11 m at
  // 2 m/s) and brakes north at 0.8 m/s^2 with the ease-out: farther than
  // v^2 / 2a = 2.5 m, and straight ahead.
  const auto& stop = s["ref_traj"]["safe_stop"];
  ASSERT_FALSE(stop.is_null());
  EXPECT_NEAR(stop["start"][0].get<double>(), 11.0, 1e-9);
  EXPECT_GT(stop["distance"].get<double>(), 2.5);
  // The stop of braking.hpp that the controller would fly from there.
  EXPECT_NEAR(stop["distance"].get<double>(),
              stop_from(Vec3::Zero(), Vec3(2.0, 0, 0), Vec3::Zero(), 0.8).distance(), 1e-9);
  EXPECT_NEAR(stop["point"][0].get<double>(), 11.0 + stop["distance"].get<double>(), 1e-9);
  EXPECT_NEAR(stop["point"][1].get<double>(), 0.0, 1e-9);
}

TEST(ViewState, BytesThatAreNotUtf8BecomeReplacementCharacters) {
  ViewState view;
  solver_stats_t solver{};
  solver.utime = 0;
  solver.status = solver_stats_t::SOLVED;
  solver.message = "ok \xff\xfe end";
  ASSERT_EQ(view.on_solver_stats(solver), "");
  EXPECT_THROW(view.snapshot().dump(), nlohmann::json::type_error);
  const auto text = ViewState::to_text(view.snapshot());
  const auto parsed = nlohmann::json::parse(text);
  EXPECT_EQ(parsed["solver"]["message"], "ok \xef\xbf\xbd\xef\xbf\xbd end");
}

TEST(ViewState, NoSafeStopWithoutTheAccelerationLimit) {
  ViewState view;
  view.on_nav_state(nav(1.0, 0.0));
  ASSERT_EQ(view.on_ref_traj(plan(1.0, 0.0)), "");
  EXPECT_TRUE(view.snapshot()["ref_traj"]["safe_stop"].is_null());
}

TEST(ViewState, TrueClearanceFromInjectedObstacles) {
  ViewState view;
  ASSERT_EQ(view.on_virtual_obstacles(one_box(20.0, 0.0)), "");
  ASSERT_EQ(view.on_nav_state(nav(1.0, 10.0)), "");
  const auto s = view.snapshot();
  // The box's near face is at north 18 m; the ground is 10 m below.
  EXPECT_NEAR(s["vehicle"]["clearance"].get<double>(), 8.0, 1e-6);
  EXPECT_EQ(s["vehicle"]["clearance_to"], "obstacle");
  EXPECT_EQ(s["obstacles"]["list"].size(), 1u);
  EXPECT_EQ(s["obstacles"]["list"][0]["kind"], "box");
}

TEST(ViewState, NarrowPassagesOfTheMissionAreShown) {
  ViewState view;
  ASSERT_EQ(view.on_mission(mission()), "");
  ASSERT_EQ(view.on_nav_state(nav(1.0, 0.0)), "");
  EXPECT_TRUE(view.snapshot()["narrow_passages"].empty());
  narrow_passages_t m{};
  m.utime = to_utime(1.0);
  m.frame = "NED";
  m.mission_id = mission().mission_id;
  m.centre = {{40.0, -5.0, -30.0}};
  m.radius = {6.5};
  m.half_height = {3.0};
  m.num_passages = 1;
  ASSERT_EQ(view.on_narrow_passages(m), "");
  auto s = view.snapshot();
  ASSERT_EQ(s["narrow_passages"].size(), 1u);
  EXPECT_DOUBLE_EQ(s["narrow_passages"][0]["centre"][1].get<double>(), -5.0);
  EXPECT_DOUBLE_EQ(s["narrow_passages"][0]["radius"].get<double>(), 6.5);
  // Another mission's list is not this one's; a bad one is rejected.
  m.utime = to_utime(2.0);
  m.mission_id += 1;
  ASSERT_EQ(view.on_narrow_passages(m), "");
  EXPECT_TRUE(view.snapshot()["narrow_passages"].empty());
  m.utime = to_utime(3.0);
  m.radius = {-1.0};
  EXPECT_NE(view.on_narrow_passages(m), "");
}

TEST(ViewState, GridCellsAreTheOccupiedOnesNearestFirst) {
  ViewStateConfig config;
  config.max_grid_cells = 2;
  ViewState view(config);
  view.on_nav_state(nav(1.0, 0.0, 0.0));
  obstacle_grid_t g{};
  g.utime = to_utime(1.0);
  g.frame = "NED";
  g.origin[0] = 0;
  g.origin[1] = 0;
  g.resolution = 1;
  g.rows = 1;
  g.cols = 4;
  g.num_cells = 4;
  g.top_altitude = {5.0f, 0.0f, 6.0f, 7.0f};
  ASSERT_EQ(view.on_obstacle_grid(g), "");
  const auto s = view.snapshot();
  EXPECT_EQ(s["grid"]["occupied"], 3);
  EXPECT_EQ(s["grid"]["left_out"], 1);
  ASSERT_EQ(s["grid"]["cells"].size(), 2u);
  // The farthest occupied cell (east 3.5 m) is the one left out.
  for (const auto& c : s["grid"]["cells"]) EXPECT_LT(c[1].get<double>(), 3.0);
}

TEST(ViewState, RejectsBadInputAndKeepsTheView) {
  ViewState view;
  ASSERT_EQ(view.on_nav_state(nav(2.0, 5.0)), "");

  auto bad = nav(3.0, std::numeric_limits<double>::quiet_NaN());
  EXPECT_NE(view.on_nav_state(bad), "");
  auto unnormalised = nav(3.0, 6.0);
  unnormalised.quaternion[0] = 2.0;
  EXPECT_NE(view.on_nav_state(unnormalised), "");
  EXPECT_EQ(view.on_nav_state(nav(1.5, 7.0)), "stamp went backwards");
  EXPECT_EQ(view.snapshot()["vehicle"]["position"][0].get<double>(), 5.0);

  auto traj = plan(2.0, 0.0);
  traj.position.pop_back();  // arrays of different lengths
  EXPECT_NE(view.on_ref_traj(traj), "");
  EXPECT_TRUE(view.snapshot()["ref_traj"].is_null());

  obstacle_grid_t grid{};
  grid.utime = to_utime(2.0);
  grid.frame = "NED";
  grid.resolution = 1;
  grid.rows = 2;
  grid.cols = 2;
  grid.num_cells = 3;  // not rows * cols
  grid.top_altitude = {1.0f, 1.0f, 1.0f};
  EXPECT_NE(view.on_obstacle_grid(grid), "");
  EXPECT_TRUE(view.snapshot()["grid"].is_null());

  const auto& c = view.counters();
  EXPECT_EQ(c.rejected_total, 5);
  EXPECT_EQ(c.accepted.at("NAV_STATE"), 1);
  EXPECT_EQ(c.rejected.at("NAV_STATE: stamp went backwards"), 1);
  EXPECT_EQ(view.snapshot()["counters"]["rejected_total"], 5);
}

TEST(ViewState, TrailIsBoundedAndSkipsHover) {
  ViewStateConfig config;
  config.trail_max_points = 50;
  config.trail_min_spacing = 0.5;
  ViewState view(config);
  for (int i = 0; i < 200; ++i) ASSERT_EQ(view.on_nav_state(nav(0.1 * i, 1.0 * i)), "");
  EXPECT_EQ(view.trail_size(), 50u);
  const auto s = view.snapshot();
  // The newest points are kept.
  EXPECT_DOUBLE_EQ(s["trail"].back()[0].get<double>(), 199.0);
  EXPECT_DOUBLE_EQ(s["trail"].front()[0].get<double>(), 150.0);
  EXPECT_DOUBLE_EQ(s["trail_length"].get<double>(), 199.0);
  // A hover moves the vehicle but adds no trail points.
  for (int i = 0; i < 20; ++i) view.on_nav_state(nav(20.0 + 0.1 * i, 199.0 + 0.01 * i));
  EXPECT_EQ(view.snapshot()["trail"].back()[0].get<double>(), 199.0);
  EXPECT_NEAR(view.snapshot()["vehicle"]["position"][0].get<double>(), 199.19, 1e-9);
}

TEST(ViewState, NavigationJumpingFarBackStartsANewTimeline) {
  ViewState view;
  ASSERT_EQ(view.on_mission(mission()), "");
  for (int i = 0; i < 100; ++i) view.on_nav_state(nav(0.1 * i, 1.0 * i));
  ASSERT_EQ(view.on_ref_traj(plan(9.9, 99.0)), "");
  // The log played again from its start.
  EXPECT_EQ(view.on_nav_state(nav(0.0, 0.0)), "");
  const auto s = view.snapshot();
  EXPECT_EQ(view.counters().timeline_resets, 1);
  EXPECT_EQ(s["trail"].size(), 1u);
  EXPECT_TRUE(s["ref_traj"].is_null());  // the old flight's plan is gone
  EXPECT_FALSE(s["mission"].is_null());  // the course is kept
  // Stamps of the new timeline are accepted on every channel again.
  EXPECT_EQ(view.on_ref_traj(plan(0.0, 0.0)), "");
}

TEST(ViewState, LayersBehindTheVehicleAreMarkedStale) {
  ViewStateConfig config;
  config.stale_after = 2.0;
  ViewState view(config);
  view.on_nav_state(nav(1.0, 0.0));
  ASSERT_EQ(view.on_ref_traj(plan(1.0, 0.0)), "");
  EXPECT_FALSE(view.snapshot()["ref_traj"]["stale"].get<bool>());
  view.on_nav_state(nav(4.0, 1.0));
  EXPECT_TRUE(view.snapshot()["ref_traj"]["stale"].get<bool>());
  EXPECT_NEAR(view.snapshot()["ref_traj"]["age"].get<double>(), 3.0, 1e-9);
}

TEST(ViewState, RejectionKindsAreBounded) {
  ViewState view;
  // Channel names without digits: each is a kind of its own.
  for (int i = 0; i < 500; ++i) {
    std::string channel = "C";
    for (int k = i; k > 0; k /= 26) channel += static_cast<char>('A' + k % 26);
    view.count_rejection(channel, "undecodable (12 bytes)");
  }
  EXPECT_EQ(view.counters().rejected.size(), kMaxRejectKinds + 1);
  EXPECT_EQ(view.counters().rejected.at(kOtherRejectKind),
            500 - static_cast<int64_t>(kMaxRejectKinds));
  EXPECT_EQ(view.counters().rejected_total, 500);
}

TEST(ViewState, ConfigIsChecked) {
  ViewStateConfig config;
  config.display_unit = "furlong";
  EXPECT_THROW(ViewState{config}, std::invalid_argument);
  config = {};
  config.trail_max_points = 1;
  EXPECT_THROW(ViewState{config}, std::invalid_argument);
  config = {};
  config.stop_accel_fraction = 0;
  EXPECT_THROW(ViewState{config}, std::invalid_argument);
}

TEST(SnapshotHub, ReaderWakesOnNewSnapshotAndOnClose) {
  SnapshotHub hub;
  EXPECT_EQ(hub.current().first, 0u);
  std::string got;
  std::thread writer([&] { hub.publish("{\"n\":1}"); });
  // The bound is past the test's own time limit: a hub that does not wake
  // its reader fails the test rather than passing it late.
  const uint64_t seq = hub.wait_newer(0, std::chrono::hours(1), got);
  writer.join();
  EXPECT_EQ(seq, 1u);
  EXPECT_EQ(got, "{\"n\":1}");
  // Nothing newer: the wait ends on close(), with nothing new.
  std::thread closer([&] { hub.close(); });
  std::string none;
  EXPECT_EQ(hub.wait_newer(1, std::chrono::hours(1), none), 1u);
  closer.join();
  EXPECT_TRUE(hub.closed());
  EXPECT_TRUE(none.empty());
}

}  // namespace
}  // namespace ofn::viewer
