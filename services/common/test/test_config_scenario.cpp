// Scenario and configuration loading: unit conversion, and errors that name
// the file and the field so that a user can fix a bad file. Each service's
// own config reader is tested beside the service.

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "config_files.hpp"
#include "ofn/common/config.hpp"
#include "ofn/common/scenario.hpp"

namespace ofn {
namespace {

using testing_support::ConfigFiles;

const std::string kOpenScenario = std::string(OFN_SOURCE_DIR) + "/sim/scenarios/open.yaml";

/// A scenario in metres that loads; the bad cases below edit it.
const char* kGoodScenario = R"(name: test
units: m
start:
  position: [0, 0, 30]
waypoints:
  - position: [0, 0, 30]
  - position: [100, 0, 30]
    capture_radius: 3
cruise_speed: 3
limits:
  max_speed: 3
  max_accel: 0.5
  max_vertical_speed: 1
)";

TEST(Scenario, OpenCourseLoadsInSI) {
  const Scenario s = load_scenario(kOpenScenario);
  EXPECT_EQ(s.name, "open");
  EXPECT_EQ(s.file, kOpenScenario);
  EXPECT_EQ(s.display_unit, "ft");
  EXPECT_DOUBLE_EQ(s.metres_per_unit, 0.3048);

  // Start at x = -100 ft, 120 ft above ground: NED down is negative.
  EXPECT_NEAR(s.start_position.x(), -30.48, 1e-9);
  EXPECT_NEAR(s.start_position.y(), 0.0, 1e-12);
  EXPECT_NEAR(s.start_position.z(), -36.576, 1e-9);
  // 10 ft/s north.
  EXPECT_NEAR(s.start_velocity.x(), 3.048, 1e-9);
  EXPECT_NEAR(s.start_velocity.y(), 0.0, 1e-9);
  EXPECT_NEAR(s.start_velocity.z(), 0.0, 1e-12);
  EXPECT_NEAR(s.start_heading, 0.0, 1e-12);

  ASSERT_EQ(s.waypoints.size(), 2u);
  EXPECT_TRUE(s.waypoints[0].position.isApprox(Vec3(-30.48, 0, -36.576)));
  EXPECT_NEAR(s.waypoints[1].position.x(), 152.4, 1e-9);
  EXPECT_NEAR(s.waypoints[1].position.z(), -36.576, 1e-9);
  EXPECT_NEAR(s.waypoints[1].capture_radius, 3.048, 1e-9);  // 10 ft
  EXPECT_GT(s.waypoints[0].capture_radius, 0.0);

  EXPECT_NEAR(s.cruise_speed, 3.048, 1e-9);
  EXPECT_NEAR(s.limits.max_speed, 3.048, 1e-9);
  EXPECT_NEAR(s.limits.max_accel, 0.48768, 1e-9);  // 1.6 ft/s^2
  EXPECT_NEAR(s.limits.max_vertical_speed, 1.524, 1e-9);
  EXPECT_NEAR(s.limits.min_forward_speed, 0.0, 1e-12);
  EXPECT_NEAR(s.limits.clearance, 6.096, 1e-9);
  EXPECT_NEAR(s.limits.sensor_range, 60.96, 1e-9);

  ASSERT_TRUE(s.start_gate.has_value());
  ASSERT_TRUE(s.finish_gate.has_value());
  EXPECT_NEAR(*s.start_gate, 0.0, 1e-12);
  EXPECT_NEAR(*s.finish_gate, 121.92, 1e-9);  // 400 ft
  EXPECT_TRUE(s.wind.isZero());
  EXPECT_DOUBLE_EQ(s.max_time, 150.0);  // seconds are not a length
}

TEST_F(ConfigFiles, GoodScenarioInMetresLoads) {
  const Scenario s = load_scenario(write("good.yaml", kGoodScenario));
  EXPECT_EQ(s.display_unit, "m");
  ASSERT_EQ(s.waypoints.size(), 2u);
  EXPECT_TRUE(s.waypoints[1].position.isApprox(Vec3(100, 0, -30)));
  EXPECT_DOUBLE_EQ(s.waypoints[1].capture_radius, 3.0);
  EXPECT_DOUBLE_EQ(s.limits.max_accel, 0.5);
  EXPECT_FALSE(s.start_gate.has_value());
}

TEST_F(ConfigFiles, MissingUnitsNamesFileAndField) {
  const std::string path = write("bad.yaml", replace(kGoodScenario, "units: m\n", ""));
  EXPECT_NAMES(scenario_error(path), path, "units");
}

TEST_F(ConfigFiles, UnknownUnitsNamesFileAndField) {
  const std::string path = write("bad.yaml", replace(kGoodScenario, "units: m", "units: yards"));
  const std::string e = scenario_error(path);
  EXPECT_NAMES(e, path, "units");
  EXPECT_NE(e.find("yards"), std::string::npos) << e;
}

TEST_F(ConfigFiles, WaypointWithTwoNumbersNamesTheWaypoint) {
  const std::string path = write(
      "bad.yaml", replace(kGoodScenario, "  - position: [0, 0, 30]", "  - position: [0, 30]"));
  EXPECT_NAMES(scenario_error(path), path, "waypoints[0].position");
}

TEST_F(ConfigFiles, SecondWaypointErrorNamesIndexOne) {
  const std::string path = write(
      "bad.yaml", replace(kGoodScenario, "  - position: [100, 0, 30]", "  - position: [100, 0]"));
  EXPECT_NAMES(scenario_error(path), path, "waypoints[1].position");
}

TEST_F(ConfigFiles, NonNumericLimitNamesTheNestedField) {
  const std::string path =
      write("bad.yaml", replace(kGoodScenario, "max_speed: 3", "max_speed: fast"));
  const std::string e = scenario_error(path);
  EXPECT_NAMES(e, path, "limits.max_speed");
  EXPECT_NE(e.find("fast"), std::string::npos) << e;
}

TEST_F(ConfigFiles, MissingRequiredLimitIsAnError) {
  const std::string path = write("bad.yaml", replace(kGoodScenario, "  max_accel: 0.5\n", ""));
  EXPECT_NAMES(scenario_error(path), path, "limits.max_accel");
}

TEST_F(ConfigFiles, UnknownTopLevelFieldIsNamed) {
  const std::string path = write("bad.yaml", std::string(kGoodScenario) + "wayponts: []\n");
  EXPECT_NAMES(scenario_error(path), path, "wayponts");
}

TEST_F(ConfigFiles, MisspeltWaypointsIsAnError) {
  // The plan itself is then missing: the error names the file and at least
  // one of the two spellings.
  const std::string path = write("bad.yaml", replace(kGoodScenario, "waypoints:", "wayponts:"));
  const std::string e = scenario_error(path);
  EXPECT_NE(e.find(path), std::string::npos) << e;
  EXPECT_TRUE(e.find("wayponts") != std::string::npos || e.find("waypoints") != std::string::npos)
      << e;
}

TEST_F(ConfigFiles, UnknownNestedFieldIsNamedWithItsPath) {
  const std::string path = write(
      "bad.yaml", replace(kGoodScenario, "  max_accel: 0.5", "  max_accel: 0.5\n  max_acel: 1"));
  EXPECT_NAMES(scenario_error(path), path, "limits.max_acel");
}

TEST_F(ConfigFiles, CruiseAboveMaxSpeedIsAnError) {
  const std::string path =
      write("bad.yaml", replace(kGoodScenario, "cruise_speed: 3", "cruise_speed: 4"));
  EXPECT_NAMES(scenario_error(path), path, "cruise_speed");
}

TEST_F(ConfigFiles, NegativeHeightIsAnError) {
  const std::string path = write("bad.yaml", replace(kGoodScenario, "  - position: [100, 0, 30]",
                                                     "  - position: [100, 0, -5]"));
  EXPECT_NAMES(scenario_error(path), path, "waypoints[1].position");
}

TEST_F(ConfigFiles, GatesInWrongOrderAreAnError) {
  const std::string path =
      write("bad.yaml", std::string(kGoodScenario) + "gates:\n  start_x: 50\n  finish_x: 10\n");
  EXPECT_NAMES(scenario_error(path), path, "gates.finish_x");
}

TEST_F(ConfigFiles, MalformedYamlNamesFileAndLine) {
  const std::string path =
      write("bad.yaml", "name: test\nunits: m\nwaypoints: [\n  - position: [0, 0\n");
  const std::string e = scenario_error(path);
  EXPECT_NE(e.find(path), std::string::npos) << e;
  EXPECT_NE(e.find("line"), std::string::npos) << e;
}

TEST_F(ConfigFiles, NonexistentFileNamesThePath) {
  const std::string path = (dir_ / "no_such_scenario.yaml").string();
  EXPECT_NE(scenario_error(path).find(path), std::string::npos);
}

TEST_F(ConfigFiles, NumbersInRangeReadOrNameTheFieldAndTheValue) {
  const std::string path =
      write("list.yaml", "good: [0.5, 1, 2]\nbad: [0.5, 7, 2]\nshort: [1, 2]\n");
  auto reader = YamlReader::load_file(path);
  EXPECT_EQ(reader.numbers_in("good", {0, 0, 0}, 0.0, 5.0), (std::vector<double>{0.5, 1, 2}));
  EXPECT_EQ(reader.numbers_in("absent", {1, 2, 3}, 0.0, 5.0), (std::vector<double>{1, 2, 3}));
  try {
    reader.numbers_in("bad", {0, 0, 0}, 0.0, 5.0);
    FAIL() << "accepted 7 in [0, 5]";
  } catch (const ConfigError& e) {
    EXPECT_NAMES(std::string(e.what()), path, "bad");
    EXPECT_NE(std::string(e.what()).find("got 7"), std::string::npos) << e.what();
  }
  EXPECT_THROW(reader.numbers_in("short", {0, 0, 0}, 0.0, 5.0), ConfigError);
}

TEST(YamlReader, NumberInRangeAndRequiredFields) {
  YAML::Node node = YAML::Load("a: 5\nb: text\nc: [1, 2]\n");
  YamlReader r(node, "mem.yaml", "top");
  EXPECT_DOUBLE_EQ(r.number("a"), 5.0);
  EXPECT_DOUBLE_EQ(r.number("missing", 7.0), 7.0);
  EXPECT_THROW(r.number_in("a", 0.0, 0.0, 4.0), ConfigError);
  EXPECT_THROW(r.number("b", 0.0), ConfigError);
  EXPECT_THROW(r.number("absent"), ConfigError);
  EXPECT_THROW(r.numbers("c", 3), ConfigError);
  EXPECT_EQ(r.numbers("c", 2), (std::vector<double>{1, 2}));
  try {
    r.number("b", 0.0);
  } catch (const ConfigError& e) {
    EXPECT_NAMES(std::string(e.what()), "mem.yaml", "top.b");
  }
}

}  // namespace
}  // namespace ofn
