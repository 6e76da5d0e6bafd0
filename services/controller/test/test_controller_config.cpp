// The controller's config file: gains, the nominal airframe, defaults,
// errors naming the file and the field.

#include <gtest/gtest.h>

#include <array>
#include <string>

#include "config_files.hpp"
#include "ofn/common/config.hpp"
#include "ofn/controller/controller_config.hpp"

namespace ofn {
namespace {

using testing_support::ConfigFiles;

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

}  // namespace
}  // namespace ofn
