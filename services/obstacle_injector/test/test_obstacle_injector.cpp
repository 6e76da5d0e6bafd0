// The obstacle injector on an in-process bus: what a subscriber to
// VIRTUAL_OBSTACLES sees as obstacles pop up and vanish on the scenario's
// schedule, and when the scenario file is edited while running.

#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "ofn/common/channels.hpp"
#include "ofn/common/config.hpp"
#include "ofn/common/logging.hpp"
#include "ofn/common/validate/virtual_obstacles.hpp"
#include "ofn/obstacle_injector/obstacle_injector_service.hpp"
#include "ofn/virtual_obstacles_t.hpp"
#include "service_test_bus.hpp"

namespace ofn {
namespace {

namespace fs = std::filesystem;
using injector::ObstacleInjectorConfig;
using injector::ObstacleInjectorService;

/// Obstacle 1 is there throughout, 2 pops up at 2 s, 3 is removed at 3 s.
const char* kScenario = R"(name: injector_test
units: m
start:
  position: [0, 0, 30]
waypoints:
  - position: [100, 0, 30]
limits:
  max_speed: 3
  max_accel: 0.5
  max_vertical_speed: 1
environment:
  ground_altitude: 4
obstacles:
  - kind: box
    center: [40, -5]
    size: [10, 20]
    height: 35
    yaw_deg: 30
  - kind: cylinder
    center: [60, 0]
    radius: 3
    height: 50
    appear_time: 2
  - kind: tree
    center: [80, 0]
    size: [12, 12]
    height: 15
    disappear_time: 3
)";

/// The same course with obstacle 1 moved and a fourth obstacle added.
const char* kEditedScenario = R"(name: injector_test
units: m
start:
  position: [0, 0, 30]
waypoints:
  - position: [100, 0, 30]
limits:
  max_speed: 3
  max_accel: 0.5
  max_vertical_speed: 1
obstacles:
  - kind: box
    center: [45, -5]
    size: [10, 20]
    height: 35
  - kind: box
    id: 4
    center: [90, 0]
    size: [5, 5]
    height: 10
)";

struct Received {
  Utime time;
  virtual_obstacles_t msg;
};

std::vector<int> ids_of(const virtual_obstacles_t& m) {
  std::vector<int> ids;
  for (const auto& o : m.obstacles) ids.push_back(o.id);
  std::sort(ids.begin(), ids.end());
  return ids;
}

bool contains(const virtual_obstacles_t& m, int id) {
  const auto ids = ids_of(m);
  return std::find(ids.begin(), ids.end(), id) != ids.end();
}

class ObstacleInjector : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { set_log_level("off"); }
  static void TearDownTestSuite() { set_log_level("info"); }

  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("ofn_injector_test_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
    path_ = (dir_ / "course.yaml").string();
    std::ofstream(path_) << kScenario;
    probe_.subscribe<virtual_obstacles_t>(channels::kVirtualObstacles,
                                          [this](const virtual_obstacles_t& m) {
                                            received_.push_back({bus_.now(), m});
                                          });
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }

  /// Replaces the scenario file; its modification time moves forward by a
  /// whole second per edit so that the change is seen whatever the
  /// file system's time resolution.
  void edit(const std::string& text) {
    const auto before = fs::last_write_time(path_);
    std::ofstream(path_, std::ios::trunc) << text;
    fs::last_write_time(path_, before + std::chrono::seconds(1));
  }

  /// Messages received at or after `from` (s).
  std::vector<Received> since(double from) const {
    std::vector<Received> out;
    for (const auto& r : received_)
      if (r.time >= to_utime(from)) out.push_back(r);
    return out;
  }

  fs::path dir_;
  std::string path_;
  testing_support::ServiceTestBus bus_{0};
  Node probe_{"probe", bus_.lcm(), bus_.clock()};
  std::vector<Received> received_;
};

TEST_F(ObstacleInjector, FirstMessageCarriesThePresentObstaclesInSI) {
  ObstacleInjectorService service(bus_.lcm(), bus_.clock(), path_);
  EXPECT_EQ(service.revision(), 0);
  bus_.advance_to(service.node(), 0);

  ASSERT_EQ(received_.size(), 1u);
  const virtual_obstacles_t& m = received_[0].msg;
  EXPECT_EQ(m.revision, 1);
  EXPECT_EQ(service.revision(), 1);
  EXPECT_DOUBLE_EQ(m.ground_altitude, 4.0);
  // The pop-up (2) is not there yet; the one removed later (3) is.
  EXPECT_EQ(ids_of(m), (std::vector<int>{1, 3}));
  EXPECT_EQ(service.present_ids(), (std::vector<int>{1, 3}));
  ASSERT_EQ(m.num_obstacles, 2);
  const obstacle_t& box = m.obstacles[0];
  EXPECT_EQ(box.id, 1);
  EXPECT_EQ(box.kind, obstacle_t::BOX);
  EXPECT_DOUBLE_EQ(box.center[0], 40);
  EXPECT_DOUBLE_EQ(box.center[1], -5);
  EXPECT_DOUBLE_EQ(box.size[0], 10);
  EXPECT_DOUBLE_EQ(box.size[1], 20);
  EXPECT_DOUBLE_EQ(box.height, 35);
  EXPECT_NEAR(box.yaw, deg2rad(30), 1e-12);
  EXPECT_EQ(m.obstacles[1].kind, obstacle_t::TREE);
  EXPECT_EQ(probe_.counters().rejected, 0);
}

TEST_F(ObstacleInjector, PopUpAppearsWithinOneCheckPeriodWithAHigherRevision) {
  ObstacleInjectorConfig config;
  config.check_rate = 20.0;
  ObstacleInjectorService service(bus_.lcm(), bus_.clock(), path_, config);
  bus_.advance_to(service.node(), to_utime(5.0));

  const auto first_with_2 = std::find_if(received_.begin(), received_.end(),
                                         [](const Received& r) { return contains(r.msg, 2); });
  ASSERT_NE(first_with_2, received_.end());
  EXPECT_GE(first_with_2->time, to_utime(2.0));
  EXPECT_LE(first_with_2->time, to_utime(2.0 + 1.0 / config.check_rate));
  ASSERT_NE(first_with_2, received_.begin());
  EXPECT_GT(first_with_2->msg.revision, std::prev(first_with_2)->msg.revision);
  // Once there, it stays.
  for (auto it = first_with_2; it != received_.end(); ++it) EXPECT_TRUE(contains(it->msg, 2));
}

TEST_F(ObstacleInjector, RemovedObstacleDisappearsAtItsTime) {
  ObstacleInjectorService service(bus_.lcm(), bus_.clock(), path_);
  bus_.advance_to(service.node(), to_utime(5.0));

  const auto first_without_3 = std::find_if(received_.begin(), received_.end(),
                                            [](const Received& r) { return !contains(r.msg, 3); });
  ASSERT_NE(first_without_3, received_.end());
  EXPECT_GE(first_without_3->time, to_utime(3.0));
  EXPECT_LE(first_without_3->time, to_utime(3.05));
  EXPECT_GT(first_without_3->msg.revision, std::prev(first_without_3)->msg.revision);
  for (auto it = received_.begin(); it != first_without_3; ++it) EXPECT_TRUE(contains(it->msg, 3));
  for (auto it = first_without_3; it != received_.end(); ++it) EXPECT_FALSE(contains(it->msg, 3));
  EXPECT_EQ(service.present_ids(), (std::vector<int>{1, 2}));
  // Start, pop-up, removal: three revisions.
  EXPECT_EQ(service.revision(), 3);
}

TEST_F(ObstacleInjector, UnchangedSetIsResentEveryPeriodWithTheSameRevision) {
  ObstacleInjectorConfig config;
  config.publish_period = 0.5;
  ObstacleInjectorService service(bus_.lcm(), bus_.clock(), path_, config);
  // Nothing changes before the pop-up at 2 s.
  bus_.advance_to(service.node(), to_utime(1.9));

  ASSERT_EQ(received_.size(), 4u);  // 0, 0.5, 1.0, 1.5 s
  for (size_t i = 0; i < received_.size(); ++i) {
    EXPECT_EQ(received_[i].time, to_utime(0.5 * static_cast<double>(i)));
    EXPECT_EQ(received_[i].msg.revision, 1);
    EXPECT_EQ(ids_of(received_[i].msg), (std::vector<int>{1, 3}));
  }
  EXPECT_EQ(service.revision(), 1);
}

TEST_F(ObstacleInjector, ResendPeriodRestartsAfterAChange) {
  ObstacleInjectorConfig config;
  config.publish_period = 0.75;
  ObstacleInjectorService service(bus_.lcm(), bus_.clock(), path_, config);
  bus_.advance_to(service.node(), to_utime(4.6));
  // Re-sends a period after the last message, whether that was a change
  // (pop-up at 2 s, removal at 3 s) or a re-send.
  std::vector<Utime> times;
  std::vector<int32_t> revisions;
  for (const auto& r : received_) {
    times.push_back(r.time);
    revisions.push_back(r.msg.revision);
  }
  const std::vector<Utime> expected_times = {0,       750000,  1500000, 2000000,
                                             2750000, 3000000, 3750000, 4500000};
  EXPECT_EQ(times, expected_times);
  EXPECT_EQ(revisions, (std::vector<int32_t>{1, 1, 1, 2, 2, 3, 3, 3}));
}

TEST_F(ObstacleInjector, BadFileEditKeepsTheOldSetAndAGoodOneIsPublished) {
  ObstacleInjectorService service(bus_.lcm(), bus_.clock(), path_);
  bus_.advance_to(service.node(), to_utime(0.5));
  ASSERT_EQ(service.revision(), 1);

  edit("obstacles:\n  - kind: pyramid\n");
  bus_.advance_to(service.node(), to_utime(1.5));
  EXPECT_EQ(service.revision(), 1);
  EXPECT_EQ(service.present_ids(), (std::vector<int>{1, 3}));
  const auto after_bad = since(0.6);
  ASSERT_FALSE(after_bad.empty());  // the re-send at 1 s
  EXPECT_EQ(after_bad.back().msg.revision, 1);
  EXPECT_EQ(ids_of(after_bad.back().msg), (std::vector<int>{1, 3}));
  EXPECT_DOUBLE_EQ(after_bad.back().msg.ground_altitude, 4.0);

  edit(kEditedScenario);
  bus_.advance_to(service.node(), to_utime(2.5));
  EXPECT_EQ(service.revision(), 2);
  EXPECT_EQ(service.present_ids(), (std::vector<int>{1, 4}));
  const auto after_good = since(1.51);
  ASSERT_FALSE(after_good.empty());
  // Published at the first check after the edit, not at the next re-send.
  EXPECT_EQ(after_good.front().time, to_utime(1.55));
  EXPECT_EQ(after_good.front().msg.revision, 2);
  EXPECT_EQ(ids_of(after_good.front().msg), (std::vector<int>{1, 4}));
  EXPECT_DOUBLE_EQ(after_good.front().msg.obstacles[0].center[0], 45.0);
  EXPECT_DOUBLE_EQ(after_good.front().msg.ground_altitude, 0.0);

  // An edit that only moves an obstacle keeps the ids but is still news.
  std::string moved = kEditedScenario;
  moved.replace(moved.find("center: [45, -5]"), 16, "center: [50, -5]");
  edit(moved);
  bus_.advance_to(service.node(), to_utime(3.0));
  EXPECT_EQ(service.revision(), 3);
  EXPECT_EQ(service.present_ids(), (std::vector<int>{1, 4}));
  const auto after_move = since(2.51);
  ASSERT_FALSE(after_move.empty());
  EXPECT_EQ(after_move.front().msg.revision, 3);
  EXPECT_DOUBLE_EQ(after_move.front().msg.obstacles[0].center[0], 50.0);
}

TEST_F(ObstacleInjector, ScheduleCountsFromTheFirstCheckNotFromClockZero) {
  // A service started late (here at clock 100 s) still pops obstacle 2 up
  // 2 s into its own mission.
  bus_.clock().set(to_utime(100.0));
  ObstacleInjectorService service(bus_.lcm(), bus_.clock(), path_);
  bus_.advance_to(service.node(), to_utime(101.9));
  EXPECT_EQ(service.present_ids(), (std::vector<int>{1, 3}));
  bus_.advance_to(service.node(), to_utime(102.0));
  EXPECT_EQ(service.present_ids(), (std::vector<int>{1, 2, 3}));
  EXPECT_NEAR(service.mission_time(), 2.0, 1e-9);
}

TEST_F(ObstacleInjector, BadScenarioAtStartIsAConfigError) {
  edit("name: broken\n");
  EXPECT_THROW(ObstacleInjectorService(bus_.lcm(), bus_.clock(), path_), ConfigError);
}

TEST(ObstacleInjectorSchedule, PresentFromAppearUntilBeforeDisappear) {
  ObstacleSpec o;
  EXPECT_TRUE(o.present_at(0.0));
  EXPECT_TRUE(o.present_at(1e6));
  o.appear_time = 2.0;
  o.disappear_time = 5.0;
  EXPECT_FALSE(o.present_at(1.999));
  EXPECT_TRUE(o.present_at(2.0));
  EXPECT_TRUE(o.present_at(4.999));
  EXPECT_FALSE(o.present_at(5.0));
}

TEST(ObstacleInjectorConfig, DefaultsAndErrorsNameTheField) {
  auto empty = YamlReader::empty("(defaults)");
  const ObstacleInjectorConfig defaults = injector::load_obstacle_injector_config(empty);
  EXPECT_DOUBLE_EQ(defaults.publish_period, 1.0);
  EXPECT_DOUBLE_EQ(defaults.check_rate, 20.0);

  YamlReader bad(YAML::Load("check_rate_hz: 0"), "injector.yaml", "");
  try {
    injector::load_obstacle_injector_config(bad);
    ADD_FAILURE() << "no ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("'check_rate_hz'"), std::string::npos) << e.what();
  }
  YamlReader typo(YAML::Load("publish_periods: 2"), "injector.yaml", "");
  EXPECT_THROW(injector::load_obstacle_injector_config(typo), ConfigError);
}

TEST(ObstacleInjectorConfig, ShippedConfigFileLoads) {
  auto reader =
      YamlReader::load_file(std::string(OFN_SOURCE_DIR) + "/config/obstacle_injector.yaml");
  const ObstacleInjectorConfig c = injector::load_obstacle_injector_config(reader);
  EXPECT_DOUBLE_EQ(c.publish_period, 1.0);
  EXPECT_DOUBLE_EQ(c.check_rate, 20.0);
}

}  // namespace
}  // namespace ofn
