// vehicle_sim's airframe failsafe on the lockstep bus: when ACTUATOR_CMD
// stops, the airframe's stabiliser flies it to a hover and the heartbeat
// says so; the next command flies again; commands that flow never wake it.

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "ofn/actuator_cmd_t.hpp"
#include "ofn/common/channels.hpp"
#include "ofn/common/config.hpp"
#include "ofn/common/logging.hpp"
#include "ofn/common/scenario.hpp"
#include "ofn/common/validate/heartbeat.hpp"
#include "ofn/heartbeat_t.hpp"
#include "ofn/sim/lockstep.hpp"
#include "ofn/vehicle_sim/vehicle_sim_service.hpp"

namespace ofn {
namespace {

const std::string kOpenCourseFile = std::string(OFN_SOURCE_DIR) + "/sim/scenarios/open.yaml";

vehicle::VehicleSimConfig sim_config() {
  auto reader = YamlReader::empty("(defaults)");
  auto c = vehicle::load_vehicle_sim_config(reader);
  c.hold_until_engaged = false;  // flying from the start, at 10 ft/s on its trim
  c.lidar.enabled = false;
  return c;
}

/// A flight computer that commands `controls` at 100 Hz while `talking`
/// says so (simulated seconds).
class FlightComputer {
 public:
  FlightComputer(sim::Lockstep& lockstep, vehicle::Controls controls,
                 std::function<bool(double)> talking)
      : node_("flight_computer", lockstep.lcm(), lockstep.clock()),
        controls_(controls),
        talking_(std::move(talking)) {
    node_.add_timer(
        0.01,
        [this] {
          if (!talking_(to_seconds(node_.now()))) return;
          actuator_cmd_t c{};
          c.utime = node_.now();
          c.collective = controls_.collective;
          c.lon_cyclic = controls_.lon_cyclic;
          c.lat_cyclic = controls_.lat_cyclic;
          c.pedal = controls_.pedal;
          node_.publish(channels::kActuatorCmd, c);
        },
        "command");
  }
  Node& node() { return node_; }

 private:
  Node node_;
  vehicle::Controls controls_;
  std::function<bool(double)> talking_;
};

class VehicleSimFailsafe : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { set_log_level("error"); }
  static void TearDownTestSuite() { set_log_level("info"); }
};

TEST_F(VehicleSimFailsafe, TheAirframesStabiliserFliesWhileCommandsStopAndHandsBack) {
  sim::Lockstep lockstep;
  const Scenario open = load_scenario(kOpenCourseFile);
  vehicle::VehicleSimService vehicle(lockstep.lcm(), lockstep.clock(), open, sim_config());
  const vehicle::Controls trim = vehicle.model().command();
  // Silent from 1 s to 7.05 s.
  FlightComputer computer(lockstep, trim, [](double t) { return t < 1.0 || t >= 7.05; });
  Node listener("listener", lockstep.lcm(), lockstep.clock());
  std::vector<std::pair<double, std::string>> states;
  listener.subscribe<heartbeat_t>(heartbeat_channel("vehicle_sim"), [&](const heartbeat_t& m) {
    states.emplace_back(to_seconds(m.utime), m.state);
  });
  std::vector<std::pair<double, double>> speeds;  // t, true speed (m/s)
  listener.add_timer(
      0.01,
      [&] {
        speeds.emplace_back(to_seconds(listener.now()), vehicle.model().state().velocity.norm());
      },
      "sample");
  lockstep.add(vehicle.node());
  lockstep.add(computer.node());
  lockstep.add(listener);

  lockstep.run(to_utime(1.0));
  EXPECT_TRUE(vehicle.failsafe().armed());
  EXPECT_FALSE(vehicle.failsafe().engaged());
  lockstep.run(to_utime(7.0));
  ASSERT_TRUE(vehicle.failsafe().engaged());
  EXPECT_EQ(vehicle.failsafe().takeovers(), 1);
  // The last command came just before 1 s; the stabiliser 0.2 s after it.
  EXPECT_NEAR(vehicle.failsafe().engaged_since(), 1.0 + 0.2, 0.02);
  double at_takeover = 0, most = 0;
  for (const auto& [t, v] : speeds) {
    if (t <= vehicle.failsafe().engaged_since())
      at_takeover = v;
    else
      most = std::max(most, v);
  }
  EXPECT_NEAR(at_takeover, 10 * 0.3048, 0.05);
  EXPECT_LE(most, at_takeover + 1e-3) << "sped up under the stabiliser";
  EXPECT_LT(speeds.back().second, 0.3) << "not slowed to a hover in 5.8 s";

  lockstep.run(to_utime(8.5));
  EXPECT_FALSE(vehicle.failsafe().engaged());
  EXPECT_EQ(vehicle.failsafe().takeovers(), 1);
  const vehicle::Controls flown = vehicle.model().command();
  EXPECT_DOUBLE_EQ(flown.collective, trim.collective);
  EXPECT_DOUBLE_EQ(flown.lon_cyclic, trim.lon_cyclic);
  EXPECT_DOUBLE_EQ(flown.lat_cyclic, trim.lat_cyclic);
  EXPECT_DOUBLE_EQ(flown.pedal, trim.pedal);
  // The heartbeat says whose flight it is.
  auto state_at = [&](double from, double to) {
    std::vector<std::string> found;
    for (const auto& [t, s] : states)
      if (t >= from && t < to) found.push_back(s);
    return found;
  };
  const auto silent = state_at(2.0, 7.0), commanded = state_at(7.5, 8.5);
  ASSERT_FALSE(silent.empty());
  ASSERT_FALSE(commanded.empty());
  for (const auto& s : silent) EXPECT_EQ(s, "failsafe");
  for (const auto& s : commanded) EXPECT_EQ(s, "running");
}

TEST_F(VehicleSimFailsafe, CommandsThatFlowNeverWakeIt) {
  sim::Lockstep lockstep;
  const Scenario open = load_scenario(kOpenCourseFile);
  vehicle::VehicleSimService vehicle(lockstep.lcm(), lockstep.clock(), open, sim_config());
  FlightComputer computer(lockstep, vehicle.model().command(), [](double) { return true; });
  lockstep.add(vehicle.node());
  lockstep.add(computer.node());
  lockstep.run(to_utime(10.0));
  EXPECT_TRUE(vehicle.failsafe().armed());
  EXPECT_EQ(vehicle.failsafe().takeovers(), 0);
}

TEST_F(VehicleSimFailsafe, OffAtZeroAndANegativeTimeoutIsNamed) {
  const std::string path = testing::TempDir() + "/failsafe_sim.yaml";
  {
    std::ofstream(path) << "command_timeout: 0\n";
    auto reader = YamlReader::load_file(path);
    auto config = vehicle::load_vehicle_sim_config(reader);
    config.hold_until_engaged = false;
    config.lidar.enabled = false;
    sim::Lockstep lockstep;
    const Scenario open = load_scenario(kOpenCourseFile);
    vehicle::VehicleSimService vehicle(lockstep.lcm(), lockstep.clock(), open, config);
    FlightComputer computer(lockstep, vehicle.model().command(), [](double t) { return t < 1.0; });
    lockstep.add(vehicle.node());
    lockstep.add(computer.node());
    lockstep.run(to_utime(3.0));
    EXPECT_FALSE(vehicle.failsafe().enabled());
    EXPECT_EQ(vehicle.failsafe().takeovers(), 0);
  }
  std::ofstream(path) << "command_timeout: -0.2\n";
  auto reader = YamlReader::load_file(path);
  try {
    vehicle::load_vehicle_sim_config(reader);
    FAIL() << "loaded";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("command_timeout"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace ofn
