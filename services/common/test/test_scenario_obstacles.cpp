// Obstacles in scenario files: the benchmark courses as BENCHMARKS.md gives
// them, in SI and NED, and errors that name the obstacle field at fault.

#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "ofn/common/config.hpp"
#include "ofn/common/frames.hpp"
#include "ofn/common/scenario.hpp"

namespace ofn {
namespace {

namespace fs = std::filesystem;

const fs::path kScenarioDir = fs::path(OFN_SOURCE_DIR) / "sim" / "scenarios";
constexpr double kFt = kMetresPerFoot;

Scenario load_course(const std::string& name) {
  return load_scenario((kScenarioDir / (name + ".yaml")).string());
}

using Kind = ObstacleSpec::Kind;

void expect_box(const ObstacleSpec& o, double x, double y, double length, double width,
                double height, double yaw_deg = 0.0) {
  EXPECT_EQ(o.kind, Kind::kBox);
  EXPECT_NEAR(o.north, x * kFt, 1e-9);
  EXPECT_NEAR(o.east, y * kFt, 1e-9);
  EXPECT_NEAR(o.length, length * kFt, 1e-9);
  EXPECT_NEAR(o.width, width * kFt, 1e-9);
  EXPECT_NEAR(o.height, height * kFt, 1e-9);
  EXPECT_NEAR(o.yaw, deg2rad(yaw_deg), 1e-12);
  EXPECT_LT(o.appear_time, 0);
  EXPECT_LT(o.disappear_time, 0);
}

TEST(ScenarioObstacles, EveryCourseFileLoads) {
  int count = 0;
  for (const auto& entry : fs::directory_iterator(kScenarioDir)) {
    if (entry.path().extension() != ".yaml") continue;
    ++count;
    EXPECT_NO_THROW(load_scenario(entry.path().string())) << entry.path();
  }
  // open, bench1..bench6, tree, popup at least.
  EXPECT_GE(count, 9);
}

TEST(ScenarioObstacles, OpenCourseHasNoObstaclesOnFlatGround) {
  const Scenario s = load_course("open");
  EXPECT_TRUE(s.obstacles.empty());
  EXPECT_EQ(s.ground_altitude, 0.0);
}

TEST(ScenarioObstacles, Bench1IsOneWallAcrossTheCourse) {
  const Scenario s = load_course("bench1");
  ASSERT_EQ(s.obstacles.size(), 1u);
  expect_box(s.obstacles[0], 200, 0, 10, 300, 140);
  EXPECT_EQ(s.obstacles[0].id, 1);
  EXPECT_NEAR(s.max_time, 200.0, 1e-9);
}

TEST(ScenarioObstacles, Bench2IsACylinderWithItsRadiusAsHalfTheSize) {
  const Scenario s = load_course("bench2");
  ASSERT_EQ(s.obstacles.size(), 1u);
  const ObstacleSpec& o = s.obstacles[0];
  EXPECT_EQ(o.kind, Kind::kCylinder);
  EXPECT_NEAR(o.north, 200 * kFt, 1e-9);
  EXPECT_NEAR(o.east, 0.0, 1e-12);
  // radius 15 ft -> a 30 ft diameter both ways.
  EXPECT_NEAR(o.length, 30 * kFt, 1e-9);
  EXPECT_NEAR(o.width, 30 * kFt, 1e-9);
  EXPECT_NEAR(o.height, 300 * kFt, 1e-9);
}

TEST(ScenarioObstacles, Bench3WallIsYawed45DegreesToTheRight) {
  const Scenario s = load_course("bench3");
  ASSERT_EQ(s.obstacles.size(), 1u);
  expect_box(s.obstacles[0], 200, 0, 10, 250, 140, 45);
  EXPECT_NEAR(s.obstacles[0].yaw, kPi / 4, 1e-12);
}

TEST(ScenarioObstacles, Bench4IsATallCube) {
  const Scenario s = load_course("bench4");
  ASSERT_EQ(s.obstacles.size(), 1u);
  expect_box(s.obstacles[0], 200, 0, 60, 60, 200);
}

TEST(ScenarioObstacles, Bench5IsTwoStaggeredWalls) {
  const Scenario s = load_course("bench5");
  ASSERT_EQ(s.obstacles.size(), 2u);
  expect_box(s.obstacles[0], 120, -95, 10, 210, 300);
  expect_box(s.obstacles[1], 320, 95, 10, 210, 300);
  EXPECT_EQ(s.obstacles[0].id, 1);
  EXPECT_EQ(s.obstacles[1].id, 2);
}

TEST(ScenarioObstacles, Bench6IsFourBlocksInTwoPairs) {
  const Scenario s = load_course("bench6");
  ASSERT_EQ(s.obstacles.size(), 4u);
  const double centres[4][2] = {{150, -50}, {150, 50}, {280, -10}, {280, 90}};
  for (int i = 0; i < 4; ++i) {
    SCOPED_TRACE(i);
    expect_box(s.obstacles[i], centres[i][0], centres[i][1], 40, 40, 300);
  }
}

TEST(ScenarioObstacles, BenchCoursesShareTheCommonSettings) {
  for (const char* name : {"bench1", "bench2", "bench3", "bench4", "bench5", "bench6"}) {
    SCOPED_TRACE(name);
    const Scenario s = load_course(name);
    EXPECT_EQ(s.display_unit, "ft");
    EXPECT_NEAR(s.start_position.z(), -120 * kFt, 1e-9);
    EXPECT_NEAR(s.limits.max_accel, 1.6 * kFt, 1e-9);
    EXPECT_NEAR(s.limits.clearance, 20 * kFt, 1e-9);
    ASSERT_TRUE(s.start_gate && s.finish_gate);
    EXPECT_NEAR(*s.finish_gate, 400 * kFt, 1e-9);
  }
}

TEST(ScenarioObstacles, TreeCourseFliesLowWithALargeClearance) {
  const Scenario s = load_course("tree");
  ASSERT_EQ(s.obstacles.size(), 1u);
  const ObstacleSpec& o = s.obstacles[0];
  EXPECT_EQ(o.kind, Kind::kTree);
  EXPECT_NEAR(o.north, 300 * kFt, 1e-9);
  EXPECT_NEAR(o.length, 60 * kFt, 1e-9);
  EXPECT_NEAR(o.width, 60 * kFt, 1e-9);
  EXPECT_NEAR(o.height, 50 * kFt, 1e-9);
  EXPECT_NEAR(s.start_position.z(), -60 * kFt, 1e-9);
  ASSERT_EQ(s.waypoints.size(), 2u);
  for (const auto& w : s.waypoints) EXPECT_NEAR(w.position.z(), -60 * kFt, 1e-9);
  EXPECT_NEAR(s.limits.clearance, 50 * kFt, 1e-9);
  EXPECT_NEAR(s.limits.max_accel, 1.65 * kFt, 1e-9);
}

TEST(ScenarioObstacles, PopupCourseHasTimedObstacles) {
  const Scenario s = load_course("popup");
  ASSERT_EQ(s.obstacles.size(), 2u);
  EXPECT_NEAR(s.obstacles[0].appear_time, 15.0, 1e-12);
  EXPECT_LT(s.obstacles[0].disappear_time, 0);
  EXPECT_LT(s.obstacles[1].appear_time, 0);
  EXPECT_NEAR(s.obstacles[1].disappear_time, 20.0, 1e-12);
}

/// A metre scenario; each test appends an obstacle list.
const char* kBase = R"(name: test
units: m
start:
  position: [0, 0, 30]
waypoints:
  - position: [100, 0, 30]
limits:
  max_speed: 3
  max_accel: 0.5
  max_vertical_speed: 1
)";

class ScenarioObstacleFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("ofn_obstacle_test_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  std::string write(const std::string& extra) {
    const fs::path p = dir_ / "scenario.yaml";
    std::ofstream(p) << kBase << extra;
    return p.string();
  }
  /// Text of the ConfigError that loading the base plus `extra` throws.
  std::string error_of(const std::string& extra) {
    const std::string path = write(extra);
    try {
      load_scenario(path);
    } catch (const ConfigError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(path), std::string::npos) << what;
      return what;
    }
    ADD_FAILURE() << "no ConfigError for:\n" << extra;
    return "";
  }
  fs::path dir_;
};

bool names(const std::string& message, const std::string& field) {
  return message.find("'" + field + "'") != std::string::npos;
}

TEST_F(ScenarioObstacleFiles, AllKindsParseWithTimesGroundAndIds) {
  const Scenario s = load_scenario(write(R"(environment:
  ground_altitude: 5
obstacles:
  - kind: box
    center: [50, -10]
    size: [8, 4]
    height: 20
    yaw_deg: -30
    appear_time: 12.5
    disappear_time: 30
  - kind: cylinder
    id: 9
    center: [60, 5]
    radius: 2
    height: 40
  - kind: tree
    center: [70, 0]
    size: [6, 7]
    height: 12
    seed: 42
  - kind: tree
    center: [80, 0]
    size: [6, 6]
    height: 12
)"));
  EXPECT_DOUBLE_EQ(s.ground_altitude, 5.0);
  ASSERT_EQ(s.obstacles.size(), 4u);
  const ObstacleSpec& box = s.obstacles[0];
  EXPECT_EQ(box.id, 1);
  EXPECT_DOUBLE_EQ(box.north, 50);
  EXPECT_DOUBLE_EQ(box.east, -10);
  EXPECT_DOUBLE_EQ(box.length, 8);
  EXPECT_DOUBLE_EQ(box.width, 4);
  EXPECT_NEAR(box.yaw, deg2rad(-30), 1e-12);
  EXPECT_DOUBLE_EQ(box.appear_time, 12.5);
  EXPECT_DOUBLE_EQ(box.disappear_time, 30);
  EXPECT_EQ(s.obstacles[1].id, 9);
  EXPECT_DOUBLE_EQ(s.obstacles[1].length, 4);
  EXPECT_EQ(s.obstacles[2].kind, Kind::kTree);
  EXPECT_EQ(s.obstacles[2].id, 3);
  EXPECT_EQ(s.obstacles[2].seed, 42);
  EXPECT_DOUBLE_EQ(s.obstacles[2].length, 6);
  EXPECT_DOUBLE_EQ(s.obstacles[2].width, 7);
  // Without a seed a tree takes its id, so trees differ by default.
  EXPECT_EQ(s.obstacles[3].seed, 4);
}

TEST_F(ScenarioObstacleFiles, FeetAreConvertedIncludingTheGround) {
  std::string text = kBase;
  text.replace(text.find("units: m"), 8, "units: ft");
  const fs::path p = dir_ / "feet.yaml";
  std::ofstream(p) << text << R"(environment:
  ground_altitude: 10
obstacles:
  - kind: cylinder
    center: [100, 0]
    radius: 10
    height: 50
)";
  const Scenario s = load_scenario(p.string());
  EXPECT_NEAR(s.ground_altitude, 10 * kFt, 1e-12);
  ASSERT_EQ(s.obstacles.size(), 1u);
  EXPECT_NEAR(s.obstacles[0].length, 20 * kFt, 1e-12);
  EXPECT_NEAR(s.obstacles[0].height, 50 * kFt, 1e-12);
}

struct BadObstacle {
  const char* what;
  const char* yaml;
  const char* field;
};

TEST_F(ScenarioObstacleFiles, EveryMistakeNamesTheField) {
  const std::vector<BadObstacle> cases = {
      {"unknown kind", "  - {kind: pyramid, center: [1, 0], size: [1, 1], height: 1}\n",
       "obstacles[0].kind"},
      {"missing kind", "  - {center: [1, 0], size: [1, 1], height: 1}\n", "obstacles[0].kind"},
      {"missing center", "  - {kind: box, size: [1, 1], height: 1}\n", "obstacles[0].center"},
      {"missing size", "  - {kind: box, center: [1, 0], height: 1}\n", "obstacles[0].size"},
      {"missing height", "  - {kind: box, center: [1, 0], size: [1, 1]}\n", "obstacles[0].height"},
      {"missing radius", "  - {kind: cylinder, center: [1, 0], height: 1}\n",
       "obstacles[0].radius"},
      {"zero width", "  - {kind: box, center: [1, 0], size: [1, 0], height: 1}\n",
       "obstacles[0].size"},
      {"negative height", "  - {kind: tree, center: [1, 0], size: [1, 1], height: -2}\n",
       "obstacles[0].height"},
      {"zero radius", "  - {kind: cylinder, center: [1, 0], radius: 0, height: 1}\n",
       "obstacles[0].radius"},
      {"radius on a box", "  - {kind: box, center: [1, 0], size: [1, 1], radius: 1, height: 1}\n",
       "obstacles[0].radius"},
      {"size on a cylinder",
       "  - {kind: cylinder, center: [1, 0], size: [1, 1], radius: 1, height: 1}\n",
       "obstacles[0].size"},
      {"yaw on a cylinder",
       "  - {kind: cylinder, center: [1, 0], radius: 1, height: 1, yaw_deg: 10}\n",
       "obstacles[0].yaw_deg"},
      {"yaw on a tree", "  - {kind: tree, center: [1, 0], size: [1, 1], height: 1, yaw_deg: 10}\n",
       "obstacles[0].yaw_deg"},
      {"seed on a box", "  - {kind: box, center: [1, 0], size: [1, 1], height: 1, seed: 3}\n",
       "obstacles[0].seed"},
      {"zero id", "  - {kind: box, id: 0, center: [1, 0], size: [1, 1], height: 1}\n",
       "obstacles[0].id"},
      {"duplicate id",
       "  - {kind: box, id: 2, center: [1, 0], size: [1, 1], height: 1}\n"
       "  - {kind: box, center: [5, 0], size: [1, 1], height: 1}\n",
       "obstacles[1].id"},
      {"disappear before appear",
       "  - {kind: box, center: [1, 0], size: [1, 1], height: 1, appear_time: 10, "
       "disappear_time: 10}\n",
       "obstacles[0].disappear_time"},
      {"disappear at the start",
       "  - {kind: box, center: [1, 0], size: [1, 1], height: 1, "
       "disappear_time: 0}\n",
       "obstacles[0].disappear_time"},
      {"negative appear",
       "  - {kind: box, center: [1, 0], size: [1, 1], height: 1, "
       "appear_time: -1}\n",
       "obstacles[0].appear_time"},
      {"misspelt field", "  - {kind: box, centre: [1, 0], size: [1, 1], height: 1}\n",
       "obstacles[0].centre"},
      {"second obstacle",
       "  - {kind: box, center: [1, 0], size: [1, 1], height: 1}\n"
       "  - {kind: box, center: [5, 0, 3], size: [1, 1], height: 1}\n",
       "obstacles[1].center"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.what);
    const std::string message = error_of(std::string("obstacles:\n") + c.yaml);
    EXPECT_TRUE(names(message, c.field)) << message;
  }
}

TEST_F(ScenarioObstacleFiles, ObstaclesThatAreNotAListAreAnError) {
  const std::string message = error_of("obstacles: {kind: box}\n");
  EXPECT_TRUE(names(message, "obstacles")) << message;
}

TEST_F(ScenarioObstacleFiles, BadGroundAltitudeNamesTheField) {
  const std::string message = error_of("environment:\n  ground_altitude: high\n");
  EXPECT_TRUE(names(message, "environment.ground_altitude")) << message;
}

}  // namespace
}  // namespace ofn
