// Log replay: a lockstep flight replayed into the mapping and planning
// services reproduces their outputs exactly; a perturbed recording is
// reported as different; bad logs and service lists are refused.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include <unistd.h>

#include <lcm/lcm-cpp.hpp>

#include "ofn/common/channels.hpp"
#include "ofn/common/config.hpp"
#include "ofn/common/logging.hpp"
#include "ofn/common/scenario.hpp"
#include "ofn/controller/controller_service.hpp"
#include "ofn/mission_uplink/mission_uplink_service.hpp"
#include "ofn/nav_state_t.hpp"
#include "ofn/obstacle_injector/obstacle_injector_service.hpp"
#include "ofn/sim/lockstep.hpp"
#include "ofn/sim/replay.hpp"
#include "ofn/vehicle_sim/vehicle_sim_service.hpp"

namespace ofn::sim {
namespace {

namespace fs = std::filesystem;

const std::string kConfigDir = std::string(OFN_SOURCE_DIR) + "/config";
const std::string kBench1 = std::string(OFN_SOURCE_DIR) + "/sim/scenarios/bench1.yaml";
// Long enough for the wall to be mapped, routed round and avoided.
constexpr double kFlightSeconds = 16.0;

YamlReader config_file(const std::string& name) {
  return YamlReader::load_file(kConfigDir + "/" + name);
}

// The lockstep runner's flight, every service in one process, recorded.
void fly_and_record(const std::string& log_path) {
  const Scenario scenario = load_scenario(kBench1);
  auto vehicle_reader = config_file("vehicle_sim.yaml");
  auto controller_reader = config_file("controller.yaml");
  auto injector_reader = config_file("obstacle_injector.yaml");
  const ReplayServiceConfigs configs = load_replay_configs(kConfigDir);
  Lockstep lockstep;
  lockstep.record(log_path);
  vehicle::VehicleSimService vehicle(lockstep.lcm(), lockstep.clock(), scenario,
                                     vehicle::load_vehicle_sim_config(vehicle_reader));
  uplink::MissionUplinkService uplink(lockstep.lcm(), lockstep.clock(), kBench1);
  control::ControllerService controller(lockstep.lcm(), lockstep.clock(),
                                        control::load_controller_config(controller_reader));
  injector::ObstacleInjectorService obstacles(
      lockstep.lcm(), lockstep.clock(), kBench1,
      injector::load_obstacle_injector_config(injector_reader));
  sensing::SensorInterfaceService sensor(lockstep.lcm(), lockstep.clock(),
                                         configs.sensor_interface);
  mapping::MapperService mapper(lockstep.lcm(), lockstep.clock(), configs.mapper);
  planning::GlobalPlannerService planner(lockstep.lcm(), lockstep.clock(), configs.global_planner);
  rh::RhOptimizerService optimizer(lockstep.lcm(), lockstep.clock(), configs.rh_optimizer);
  for (Node* node : {&vehicle.node(), &uplink.node(), &controller.node(), &obstacles.node(),
                     &sensor.node(), &mapper.node(), &planner.node(), &optimizer.node()})
    lockstep.add(*node);
  lockstep.run(to_utime(kFlightSeconds));
}

// Copies a log, letting `edit` change or drop (return false) each event.
void copy_log(const std::string& from, const std::string& to,
              const std::function<bool(lcm::LogEvent&, std::vector<uint8_t>&)>& edit) {
  lcm::LogFile in(from, "r");
  lcm::LogFile out(to, "w");
  ASSERT_TRUE(in.good() && out.good());
  while (const lcm::LogEvent* e = in.readNextEvent()) {
    lcm::LogEvent copy = *e;
    const auto* data = static_cast<const uint8_t*>(e->data);
    std::vector<uint8_t> bytes(data, data + e->datalen);
    if (!edit(copy, bytes)) continue;
    copy.data = bytes.data();
    copy.datalen = static_cast<int32_t>(bytes.size());
    out.writeEvent(&copy);
  }
}

std::map<std::string, int64_t> channel_counts(const std::string& path) {
  lcm::LogFile in(path, "r");
  std::map<std::string, int64_t> counts;
  while (const lcm::LogEvent* e = in.readNextEvent()) ++counts[e->channel];
  return counts;
}

const ChannelComparison& channel(const ReplayResult& result, const std::string& name) {
  for (const auto& c : result.channels)
    if (c.channel == name) return c;
  throw std::runtime_error("no comparison for " + name);
}

class LogReplay : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    set_log_level("off");
    dir_ = fs::temp_directory_path() / ("ofn-replay-test-" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    flight_ = (dir_ / "flight.lcm").string();
    fly_and_record(flight_);
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }

  static ReplayOptions options(const std::string& services) {
    ReplayOptions o;
    o.services = parse_service_list(services);
    o.configs = load_replay_configs(kConfigDir);
    return o;
  }

  static fs::path dir_;
  static std::string flight_;
};

fs::path LogReplay::dir_;
std::string LogReplay::flight_;

TEST_F(LogReplay, LockstepFlightReplaysIdenticallyThroughMapperAndPlanners) {
  ReplayOptions o = options("sensor_interface,mapper,global_planner,rh_optimizer");
  o.replayed_log_path = (dir_ / "replayed.lcm").string();
  const ReplayResult result = replay_log(flight_, o);
  SCOPED_TRACE(format_comparison(result));
  EXPECT_TRUE(result.matches());
  ASSERT_EQ(result.channels.size(), 8u);  // SCAN_WORLD ... NARROW_PASSAGES, SCANNER_STATUS too
  for (const auto& c : result.channels) {
    EXPECT_EQ(c.identical, c.recorded) << c.channel;
    EXPECT_EQ(c.replayed, c.recorded) << c.channel;
  }
  // The flight must have exercised the whole chain for this to mean anything.
  EXPECT_GT(channel(result, channels::kScanWorld).recorded, 100);
  EXPECT_GT(channel(result, channels::kCuboids).recorded, 10);
  EXPECT_GT(channel(result, channels::kGlobalPath).recorded, 5);
  EXPECT_GT(channel(result, channels::kRefTraj).recorded, 10);
  EXPECT_GT(channel(result, channels::kNarrowPassages).recorded, 5);

  // The replayed log holds the same traffic as the recording, with the
  // replayed services' outputs in place of the recorded ones.
  const auto recorded = channel_counts(flight_);
  const auto replayed = channel_counts(o.replayed_log_path);
  for (const char* ch : {channels::kNavState, channels::kLidarRaw, channels::kScanWorld,
                         channels::kObstacleGrid, channels::kRefTraj, channels::kSolverStats})
    EXPECT_EQ(replayed.at(ch), recorded.at(ch)) << ch;
}

TEST_F(LogReplay, PlannersAloneReproduceFromTheRecordedMap) {
  const ReplayResult result = replay_log(flight_, options("global_planner,rh_optimizer"));
  SCOPED_TRACE(format_comparison(result));
  EXPECT_TRUE(result.matches());
  EXPECT_EQ(channel(result, channels::kRefTraj).identical,
            channel(result, channels::kRefTraj).recorded);
}

TEST_F(LogReplay, DroppedScansAreReportedAsDifferent) {
  const std::string perturbed = (dir_ / "fewer_scans.lcm").string();
  int scan = 0;
  copy_log(flight_, perturbed, [&](lcm::LogEvent& e, std::vector<uint8_t>&) {
    return e.channel != channels::kScanWorld || ++scan % 4 != 0;
  });
  const ReplayResult result = replay_log(perturbed, options("mapper"));
  SCOPED_TRACE(format_comparison(result));
  EXPECT_FALSE(result.matches());
  const ChannelComparison& grid = channel(result, channels::kObstacleGrid);
  EXPECT_EQ(grid.missing, scan / 4);
  EXPECT_LT(grid.replayed, grid.recorded);
}

TEST_F(LogReplay, ShiftedNavigationIsReportedAsDifferent) {
  const std::string perturbed = (dir_ / "shifted_nav.lcm").string();
  copy_log(flight_, perturbed, [&](lcm::LogEvent& e, std::vector<uint8_t>& bytes) {
    if (e.channel != channels::kNavState) return true;
    nav_state_t nav;
    nav.decode(bytes.data(), 0, static_cast<int>(bytes.size()));
    nav.position[1] += 3.0;  // 3 m east
    bytes.resize(static_cast<size_t>(nav.getEncodedSize()));
    nav.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
    return true;
  });
  const ReplayResult result = replay_log(perturbed, options("global_planner"));
  SCOPED_TRACE(format_comparison(result));
  EXPECT_FALSE(result.matches());
  const ChannelComparison& path = channel(result, channels::kGlobalPath);
  EXPECT_LT(path.identical, path.recorded);
  EXPECT_GT(path.largest_difference, 0.5);
}

TEST_F(LogReplay, ToleranceAcceptsSmallDifferencesOnly) {
  const std::string perturbed = (dir_ / "nudged_nav.lcm").string();
  copy_log(flight_, perturbed, [&](lcm::LogEvent& e, std::vector<uint8_t>& bytes) {
    if (e.channel != channels::kNavState) return true;
    nav_state_t nav;
    nav.decode(bytes.data(), 0, static_cast<int>(bytes.size()));
    nav.position[0] += 1e-3;  // 1 mm north
    nav.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
    return true;
  });
  ReplayOptions o = options("global_planner");
  const ReplayResult exact = replay_log(perturbed, o);
  EXPECT_FALSE(exact.matches());
  o.tolerance = 0.05;
  const ReplayResult tolerant = replay_log(perturbed, o);
  SCOPED_TRACE(format_comparison(tolerant));
  EXPECT_TRUE(tolerant.matches());
  EXPECT_GT(channel(tolerant, channels::kGlobalPath).within_tolerance, 0);
}

TEST_F(LogReplay, BadInputIsRefusedWithAReason) {
  const ReplayOptions o = options("mapper");
  auto refused = [&](const std::string& path, const std::string& reason) {
    try {
      replay_log(path, o);
      ADD_FAILURE() << path << " was accepted";
    } catch (const ReplayInputError& e) {
      EXPECT_NE(std::string(e.what()).find(reason), std::string::npos) << e.what();
    }
  };
  refused((dir_ / "no_such.lcm").string(), "not found");
  const std::string garbage = (dir_ / "garbage.lcm").string();
  std::ofstream(garbage) << std::string(4096, 'x');
  refused(garbage, "no LCM events");
  refused(dir_.string(), "not a regular file");
  const std::string no_scans = (dir_ / "no_scans.lcm").string();
  copy_log(flight_, no_scans, [](lcm::LogEvent& e, std::vector<uint8_t>&) {
    return e.channel != channels::kScanWorld;
  });
  refused(no_scans, "no SCAN_WORLD messages");

  EXPECT_THROW(parse_service_list("mapper,controller"), ReplayInputError);
  EXPECT_THROW(parse_service_list("mapper,mapper"), ReplayInputError);
  EXPECT_THROW(parse_service_list(""), ReplayInputError);
  EXPECT_EQ(parse_service_list("rh_optimizer,mapper"),
            (std::vector<std::string>{"mapper", "rh_optimizer"}));
}

}  // namespace
}  // namespace ofn::sim
