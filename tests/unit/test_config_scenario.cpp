// Scenario and configuration loading: unit conversion, and errors that name
// the file and the field so that a user can fix a bad file.

#include <gtest/gtest.h>

#include <unistd.h>

#include <array>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "ofn/common/config.hpp"
#include "ofn/common/scenario.hpp"
#include "ofn/controller/controller_service.hpp"
#include "ofn/rh_optimizer/rh_optimizer_service.hpp"
#include "ofn/vehicle_sim/vehicle_sim_service.hpp"

namespace ofn {
namespace {

namespace fs = std::filesystem;

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

class ConfigFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("ofn_config_test_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  std::string write(const std::string& name, const std::string& text) {
    const fs::path p = dir_ / name;
    std::ofstream(p) << text;
    return p.string();
  }
  /// Text of the ConfigError that loading `path` as a scenario throws.
  static std::string scenario_error(const std::string& path) {
    try {
      load_scenario(path);
    } catch (const ConfigError& e) {
      return e.what();
    } catch (const std::exception& e) {
      ADD_FAILURE() << "not a ConfigError: " << e.what();
      return "";
    }
    ADD_FAILURE() << path << " loaded without error";
    return "";
  }
  static std::string replace(std::string text, const std::string& from, const std::string& to) {
    const size_t at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    if (at != std::string::npos) text.replace(at, from.size(), to);
    return text;
  }

  fs::path dir_;
};

#define EXPECT_NAMES(message, path, field)              \
  do {                                                  \
    const std::string m_ = (message);                   \
    EXPECT_NE(m_.find(path), std::string::npos) << m_;  \
    EXPECT_NE(m_.find(field), std::string::npos) << m_; \
  } while (0)

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

TEST_F(ConfigFiles, ControllerConfigUnknownOuterLoopFieldIsNamed) {
  const std::string path = write("controller.yaml", "outer_loop:\n  position_gian: [1, 1, 1]\n");
  auto reader = YamlReader::load_file(path);
  try {
    control::load_controller_config(reader);
    FAIL() << "loaded";
  } catch (const ConfigError& e) {
    EXPECT_NAMES(std::string(e.what()), path, "outer_loop.position_gian");
  }
}

TEST_F(ConfigFiles, ControllerConfigNegativeGainIsAnError) {
  const std::string path =
      write("controller.yaml", "outer_loop:\n  velocity_gain: [1.4, -1.4, 1.8]\n");
  auto reader = YamlReader::load_file(path);
  try {
    control::load_controller_config(reader);
    FAIL() << "loaded";
  } catch (const ConfigError& e) {
    EXPECT_NAMES(std::string(e.what()), path, "outer_loop.velocity_gain");
  }
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

TEST_F(ConfigFiles, ControllerConfigReadsGains) {
  const std::string path = write("controller.yaml",
                                 "rate_hz: 50\nouter_loop:\n  position_gain: [0.5, 0.6, 0.7]\n"
                                 "  max_tilt_deg: 20\ninner_loop:\n  rate_gain: [5, 5, 3]\n");
  auto reader = YamlReader::load_file(path);
  const auto c = control::load_controller_config(reader);
  EXPECT_DOUBLE_EQ(c.rate, 50.0);
  EXPECT_TRUE(c.gains.position.isApprox(Vec3(0.5, 0.6, 0.7)));
  EXPECT_NEAR(c.gains.max_tilt, deg2rad(20), 1e-12);
  EXPECT_TRUE(c.gains.rate.isApprox(Vec3(5, 5, 3)));
  // Untouched fields keep their defaults.
  EXPECT_TRUE(c.gains.velocity.isApprox(control::ControllerGains{}.velocity));
}

TEST(ControllerConfig, DefaultsLoadFromAnEmptyReader) {
  auto reader = YamlReader::empty("(defaults)");
  const auto c = control::load_controller_config(reader);
  EXPECT_DOUBLE_EQ(c.rate, 100.0);
  EXPECT_TRUE(c.gains.position.isApprox(control::ControllerGains{}.position));
}

/// Every parameter of an airframe, in one list, to compare two bit for bit.
std::vector<double> every_parameter(const vehicle::RotorcraftParams& p) {
  std::vector<double> v = {
      p.mass,           p.inertia.x(),         p.inertia.y(),           p.inertia.z(),
      p.air_density,    p.rotor_radius,        p.rotor_speed,           p.lift_slope,
      p.solidity,       p.profile_drag,        p.inflow_time_constant,  p.hub_height,
      p.flap_stiffness, p.flap_time_constant,  p.cyclic_to_flap,        p.flap_blowback,
      p.tail_arm,       p.tail_thrust_per_rad, p.tail_velocity_damping, p.drag_area.x(),
      p.drag_area.y(),  p.drag_area.z(),       p.servo_time_constant};
  for (const vehicle::Controls* c : {&p.min_controls, &p.max_controls, &p.actuator_rate})
    for (double x : c->as_array()) v.push_back(x);
  return v;
}

TEST(ControllerConfig, ShippedNominalAirframeIsTheShippedSimulatedOne) {
  // The controller's model is exact until a scenario varies the airframe,
  // as it was when the model was the simulator's own.
  auto controller_reader =
      YamlReader::load_file(std::string(OFN_SOURCE_DIR) + "/config/controller.yaml");
  auto sim_reader = YamlReader::load_file(std::string(OFN_SOURCE_DIR) + "/config/vehicle_sim.yaml");
  const auto nominal = control::load_controller_config(controller_reader).nominal;
  const auto flown = vehicle::load_vehicle_sim_config(sim_reader).params;
  EXPECT_EQ(every_parameter(nominal), every_parameter(flown));
  EXPECT_EQ(every_parameter(nominal), every_parameter(vehicle::RotorcraftParams{}));
  auto empty = YamlReader::empty("(defaults)");
  EXPECT_EQ(every_parameter(control::load_controller_config(empty).nominal),
            every_parameter(vehicle::RotorcraftParams{}));
}

TEST(RhOptimizerConfig, ShippedCommitWindowCoversWhatTheControllerFliesAlone) {
  // The controller flies a plan until ref_traj_timeout after its stamp and
  // then that plan's stop; the optimiser checks the stop from every instant
  // of commit_time after the stamp. The window must hold the timeout, one
  // control period, and the lag of the controller's clock behind the
  // optimiser's (two SIM_CLOCK followers over a delayed link).
  auto controller_reader =
      YamlReader::load_file(std::string(OFN_SOURCE_DIR) + "/config/controller.yaml");
  auto optimiser_reader =
      YamlReader::load_file(std::string(OFN_SOURCE_DIR) + "/config/rh_optimizer.yaml");
  const auto controller = control::load_controller_config(controller_reader);
  const auto optimiser = rh::load_rh_optimizer_config(optimiser_reader);
  const double control_period = 1.0 / controller.rate;
  constexpr double kClockLag = 0.1;  // s
  EXPECT_GE(optimiser.commit.commit_time, controller.ref_traj_timeout + control_period + kClockLag);
}

TEST_F(ConfigFiles, ControllerConfigReadsTheNominalAirframe) {
  const std::string path = write("controller.yaml",
                                 "nominal_airframe:\n  mass: 90\n  rotor_radius: 1.6\n"
                                 "  drag_area: [0.4, 1.2, 1.4]\n"
                                 "  max_controls: [0.32, 0.15, 0.17, 0.45]\n");
  auto reader = YamlReader::load_file(path);
  const auto p = control::load_controller_config(reader).nominal;
  const vehicle::RotorcraftParams base;
  EXPECT_DOUBLE_EQ(p.mass, 90.0);
  EXPECT_DOUBLE_EQ(p.rotor_radius, 1.6);
  EXPECT_TRUE(p.drag_area.isApprox(Vec3(0.4, 1.2, 1.4)));
  EXPECT_EQ(p.max_controls.as_array(), (std::array<double, 4>{0.32, 0.15, 0.17, 0.45}));
  // Untouched parameters keep the simulated airframe's values.
  EXPECT_EQ(p.min_controls.as_array(), base.min_controls.as_array());
  EXPECT_EQ(p.tail_arm, base.tail_arm);
}

TEST_F(ConfigFiles, ControllerConfigBadNominalAirframeValueIsAnError) {
  for (const std::string bad :
       {"rotor_radius: 0", "cyclic_to_flap: -1", "inertia: [8, 0, 18]",
        "actuator_rate: [1.5, 1.5, 1.5]", "min_controls: [-0.05, -0.16, -0.16, -2]"}) {
    const std::string key = bad.substr(0, bad.find(':'));
    const std::string path = write("controller.yaml", "nominal_airframe:\n  " + bad + "\n");
    auto reader = YamlReader::load_file(path);
    try {
      control::load_controller_config(reader);
      ADD_FAILURE() << "loaded " << bad;
    } catch (const ConfigError& e) {
      EXPECT_NAMES(std::string(e.what()), path, "nominal_airframe." + key);
    }
  }
}

TEST_F(ConfigFiles, ControllerConfigControlLimitsOutOfOrderAreAnError) {
  const std::string path = write("controller.yaml",
                                 "nominal_airframe:\n  min_controls: [-0.05, -0.16, -0.16, -0.4]\n"
                                 "  max_controls: [0.30, -0.2, 0.16, 0.4]\n");
  auto reader = YamlReader::load_file(path);
  try {
    control::load_controller_config(reader);
    FAIL() << "loaded";
  } catch (const ConfigError& e) {
    EXPECT_NAMES(std::string(e.what()), path, "nominal_airframe.max_controls");
  }
}

TEST_F(ConfigFiles, VehicleSimNavRateAbovePhysicsRateIsAnError) {
  const std::string path = write("sim.yaml", "physics_rate_hz: 200\nnav_rate_hz: 500\n");
  auto reader = YamlReader::load_file(path);
  try {
    vehicle::load_vehicle_sim_config(reader);
    FAIL() << "loaded";
  } catch (const ConfigError& e) {
    EXPECT_NAMES(std::string(e.what()), path, "nav_rate_hz");
  }
}

TEST_F(ConfigFiles, VehicleSimConfigReadsAirframe) {
  const std::string path =
      write("sim.yaml", "physics_rate_hz: 500\nairframe:\n  mass: 70\n  inertia: [7, 20, 16]\n");
  auto reader = YamlReader::load_file(path);
  const auto c = vehicle::load_vehicle_sim_config(reader);
  EXPECT_DOUBLE_EQ(c.physics_rate, 500.0);
  EXPECT_DOUBLE_EQ(c.params.mass, 70.0);
  EXPECT_TRUE(c.params.inertia.isApprox(Vec3(7, 20, 16)));
}

TEST_F(ConfigFiles, VehicleSimUnknownAirframeFieldIsNamed) {
  const std::string path = write("sim.yaml", "airframe:\n  mas: 70\n");
  auto reader = YamlReader::load_file(path);
  try {
    vehicle::load_vehicle_sim_config(reader);
    FAIL() << "loaded";
  } catch (const ConfigError& e) {
    EXPECT_NAMES(std::string(e.what()), path, "airframe.mas");
  }
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
