// vehicle_sim's service: its config file (rates, the airframe, the LIDAR
// section: defaults, degrees, the shipped file, errors naming the file and
// the field) and LIDAR_RAW of the injected obstacles on an in-process bus.

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "config_files.hpp"
#include "ofn/common/channels.hpp"
#include "ofn/common/config.hpp"
#include "ofn/common/logging.hpp"
#include "ofn/common/obstacle_messages.hpp"
#include "ofn/common/scenario.hpp"
#include "ofn/common/validate/lidar_scan.hpp"
#include "ofn/lidar_scan_t.hpp"
#include "ofn/vehicle_sim/vehicle_sim_service.hpp"
#include "ofn/virtual_obstacles_t.hpp"
#include "service_test_bus.hpp"

namespace ofn::vehicle {
namespace {

using testing_support::ConfigFiles;

constexpr int kWallId = 5;

/// A wall across the north at `north_face`, far above every beam.
ObstacleSpec wall_spec(double north_face, double ground_altitude) {
  ObstacleSpec s;
  s.kind = ObstacleSpec::Kind::kBox;
  s.id = kWallId;
  s.north = north_face + 0.5;
  s.length = 1.0;
  s.width = 400.0;
  s.height = 2000.0 - ground_altitude;
  return s;
}

TEST_F(ConfigFiles, VehicleSimNavRateAbovePhysicsRateIsAnError) {
  const std::string path = write("sim.yaml", "physics_rate_hz: 200\nnav_rate_hz: 500\n");
  auto reader = YamlReader::load_file(path);
  try {
    load_vehicle_sim_config(reader);
    FAIL() << "loaded";
  } catch (const ConfigError& e) {
    EXPECT_NAMES(std::string(e.what()), path, "nav_rate_hz");
  }
}

TEST_F(ConfigFiles, VehicleSimConfigReadsAirframe) {
  const std::string path =
      write("sim.yaml", "physics_rate_hz: 500\nairframe:\n  mass: 70\n  inertia: [7, 20, 16]\n");
  auto reader = YamlReader::load_file(path);
  const auto c = load_vehicle_sim_config(reader);
  EXPECT_DOUBLE_EQ(c.physics_rate, 500.0);
  EXPECT_DOUBLE_EQ(c.params.mass, 70.0);
  EXPECT_TRUE(c.params.inertia.isApprox(Vec3(7, 20, 16)));
}

TEST_F(ConfigFiles, VehicleSimUnknownAirframeFieldIsNamed) {
  const std::string path = write("sim.yaml", "airframe:\n  mas: 70\n");
  auto reader = YamlReader::load_file(path);
  try {
    load_vehicle_sim_config(reader);
    FAIL() << "loaded";
  } catch (const ConfigError& e) {
    EXPECT_NAMES(std::string(e.what()), path, "airframe.mas");
  }
}

class LidarConfigFile : public ::testing::Test {
 protected:
  // Parsed in memory: a shared file would be overwritten by the suite's other tests,
  // which ctest runs in parallel processes.
  VehicleSimConfig load(const std::string& text) {
    YamlReader reader(YAML::Load(text), "lidar_sim.yaml", "");
    return load_vehicle_sim_config(reader);
  }
  void expect_error_names(const std::string& text, const std::string& field) {
    try {
      load(text);
      FAIL() << "loaded: " << text;
    } catch (const ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
    }
  }
};

TEST_F(LidarConfigFile, DefaultsAndDegreesAreConverted) {
  auto empty = YamlReader::empty("(defaults)");
  const LidarConfig d = load_vehicle_sim_config(empty).lidar;
  EXPECT_TRUE(d.enabled);
  EXPECT_DOUBLE_EQ(d.scan_rate, 12.5);
  EXPECT_EQ(d.layers, 4);
  EXPECT_NEAR(d.elevation_min, deg2rad(-42.5), 1e-12);
  EXPECT_DOUBLE_EQ(d.dropout_probability, 0.01);
  EXPECT_DOUBLE_EQ(d.saturation_range, 1.0);

  const LidarConfig c = load(
                            "lidar:\n  scan_rate_hz: 10\n  layers: 2\n  elevation_max_deg: 30\n"
                            "  angular_resolution_deg: 0.5\n  saturation_probability: 0.2\n"
                            "  mount_offset: [0.5, 0, 0.3]\n  mount_rpy_deg: [0, -10, 0]\n"
                            "  seed: 7\n")
                            .lidar;
  EXPECT_DOUBLE_EQ(c.scan_rate, 10);
  EXPECT_EQ(c.layers, 2);
  EXPECT_NEAR(c.elevation_max, deg2rad(30), 1e-12);
  EXPECT_NEAR(c.angular_resolution, deg2rad(0.5), 1e-12);
  EXPECT_DOUBLE_EQ(c.saturation_probability, 0.2);
  EXPECT_TRUE(c.mount_offset.isApprox(Vec3(0.5, 0, 0.3)));
  EXPECT_NEAR(c.mount_rpy.y(), deg2rad(-10), 1e-12);
  EXPECT_EQ(c.seed, 7u);
}

TEST_F(LidarConfigFile, TheShippedConfigStatesTheDefaults) {
  auto reader = YamlReader::load_file(std::string(OFN_SOURCE_DIR) + "/config/vehicle_sim.yaml");
  const LidarConfig c = load_vehicle_sim_config(reader).lidar;
  const LidarConfig d;
  EXPECT_EQ(c.enabled, d.enabled);
  EXPECT_DOUBLE_EQ(c.scan_rate, d.scan_rate);
  EXPECT_EQ(c.layers, d.layers);
  EXPECT_NEAR(c.layer_spacing, d.layer_spacing, 1e-12);
  EXPECT_NEAR(c.elevation_min, d.elevation_min, 1e-12);
  EXPECT_NEAR(c.elevation_max, d.elevation_max, 1e-12);
  EXPECT_NEAR(c.angular_resolution, d.angular_resolution, 1e-12);
  EXPECT_DOUBLE_EQ(c.max_range, d.max_range);
  EXPECT_DOUBLE_EQ(c.min_range, d.min_range);
  EXPECT_DOUBLE_EQ(c.range_noise_sigma, d.range_noise_sigma);
  EXPECT_DOUBLE_EQ(c.dropout_probability, d.dropout_probability);
  EXPECT_DOUBLE_EQ(c.outlier_probability, d.outlier_probability);
  EXPECT_DOUBLE_EQ(c.saturation_range, d.saturation_range);
  EXPECT_DOUBLE_EQ(c.saturation_probability, d.saturation_probability);
  EXPECT_EQ(c.seed, d.seed);
  EXPECT_EQ(c.mount_offset, d.mount_offset);
  EXPECT_EQ(c.mount_rpy, d.mount_rpy);
}

TEST_F(LidarConfigFile, BadValuesNameTheField) {
  expect_error_names("lidar:\n  dropout_probability: 1.5\n", "lidar.dropout_probability");
  expect_error_names("lidar:\n  layers: 0\n", "lidar.layers");
  expect_error_names("lidar:\n  elevation_min_deg: 10\n  elevation_max_deg: 5\n",
                     "lidar.elevation_max_deg");
  expect_error_names("lidar:\n  angular_resolution_deg: 0.01\n", "lidar.angular_resolution_deg");
  expect_error_names("lidar:\n  scan_rate: 10\n", "lidar.scan_rate");
  expect_error_names("lidar:\n  max_range: 10\n  min_range: 20\n", "lidar.min_range");
}

class LidarOnTheBus : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { set_log_level("error"); }
  static void TearDownTestSuite() { set_log_level("info"); }
};

TEST_F(LidarOnTheBus, VehicleSimPublishesScansOfTheInjectedObstacles) {
  const Scenario scenario = load_scenario(std::string(OFN_SOURCE_DIR) + "/sim/scenarios/open.yaml");
  testing_support::ServiceTestBus bus(0);
  auto reader = YamlReader::empty("(defaults)");
  VehicleSimConfig config = load_vehicle_sim_config(reader);
  config.lidar.range_noise_sigma = 0;
  config.lidar.dropout_probability = 0;
  VehicleSimService vehicle(bus.lcm(), bus.clock(), scenario, config);

  // A wall 20 m ahead of the held start position, as the injector would send it.
  Node injector("test_injector", bus.lcm(), bus.clock());
  const double wall_face = scenario.start_position.x() + 20.0;
  injector.add_timer(
      0.5,
      [&] {
        virtual_obstacles_t m;
        m.utime = injector.now();
        m.revision = 1;
        m.ground_altitude = scenario.ground_altitude;
        m.obstacles = {to_message(wall_spec(wall_face, scenario.ground_altitude))};
        m.num_obstacles = 1;
        injector.publish(channels::kVirtualObstacles, m);
      },
      "obstacles");
  Node recorder("test_recorder", bus.lcm(), bus.clock());
  std::vector<lidar_scan_t> scans;
  recorder.subscribe<lidar_scan_t>(channels::kLidarRaw,
                                   [&](const lidar_scan_t& m) { scans.push_back(m); });
  bus.advance_to({&vehicle.node(), &injector, &recorder}, to_utime(2.0));

  EXPECT_EQ(recorder.counters().rejected, 0);
  ASSERT_GE(scans.size(), 23u);  // 12.5 Hz for 2 s
  EXPECT_EQ(vehicle.world().obstacles().size(), 1u);
  EXPECT_NEAR(scans.front().max_range, scenario.limits.sensor_range, 1e-9);
  for (size_t k = 1; k < scans.size(); ++k) {
    EXPECT_EQ(scans[k].scan_index, scans[k - 1].scan_index + 1);
    EXPECT_EQ(scans[k].utime - scans[k - 1].utime, 80'000);
  }
  // The last scan sees the wall ahead: the level beams measure about 20 m
  // (the held trim attitude tilts the head a little).
  const lidar_scan_t& last = scans.back();
  EXPECT_EQ(last.num_beams, vehicle.lidar().beams_per_scan());
  int near_level = 0;
  for (int i = 0; i < last.num_beams; ++i) {
    if (std::abs(last.elevation[i]) > deg2rad(2.0)) continue;
    ASSERT_EQ(last.status[i], lidar_scan_t::OK);
    EXPECT_NEAR(last.range[i], 20.0, 1.0);
    ++near_level;
  }
  EXPECT_GT(near_level, 50);
}

}  // namespace
}  // namespace ofn::vehicle
