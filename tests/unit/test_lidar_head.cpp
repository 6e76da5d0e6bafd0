// The simulated LIDAR head: beam layout and timing, ranges against known
// geometry, the status flags and fault injection, motion during a scan,
// determinism, and LIDAR_RAW from vehicle_sim on the lockstep bus.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <vector>

#include "ofn/common/channels.hpp"
#include "ofn/common/config.hpp"
#include "ofn/common/logging.hpp"
#include "ofn/common/obstacle_messages.hpp"
#include "ofn/common/scenario.hpp"
#include "ofn/common/validate/lidar_scan.hpp"
#include "ofn/lidar_scan_t.hpp"
#include "ofn/sim/lockstep.hpp"
#include "ofn/vehicle_sim/lidar_head.hpp"
#include "ofn/vehicle_sim/vehicle_sim_service.hpp"
#include "ofn/virtual_obstacles_t.hpp"

namespace ofn::vehicle {
namespace {

constexpr int kWallId = 5;

ObstacleSpec wall_spec(double north_face, double ground_altitude) {
  ObstacleSpec s;
  s.kind = ObstacleSpec::Kind::kBox;
  s.id = kWallId;
  s.north = north_face + 0.5;
  s.length = 1.0;
  s.width = 400.0;
  s.height = 2000.0 - ground_altitude;  // far above every beam
  return s;
}

/// A wall across the north at `north_face`, the ground out of reach.
world::World wall_world(double north_face = 20.0) {
  return world::World({wall_spec(north_face, -1000.0)}, -1000.0);
}

/// Noise and random faults off.
LidarConfig exact_config() {
  LidarConfig c;
  c.range_noise_sigma = 0;
  c.dropout_probability = 0;
  return c;
}

PoseAt level_at(const Vec3& position, double yaw = 0.0) {
  return [=](Utime) { return std::make_pair(position, quat_from_euler(0, 0, yaw)); };
}

const Vec3 kAt10m(0, 0, -10);

TEST(LidarHead, BeamLayoutIsLayersTimesElevationSteps) {
  LidarHead head(LidarConfig{}, 0.0);
  EXPECT_EQ(head.elevation_steps(), 341);  // -42.5 .. 42.5 deg every 0.25 deg
  EXPECT_EQ(head.beams_per_scan(), 4 * 341);
  const LidarScan scan = head.scan(0, level_at(kAt10m), world::World());
  ASSERT_EQ(static_cast<int>(scan.beams.size()), head.beams_per_scan());
  std::set<float> layers;
  for (const auto& b : scan.beams) layers.insert(b.layer_angle);
  const std::vector<float> expected_layers = {
      static_cast<float>(deg2rad(-1.2)), static_cast<float>(deg2rad(-0.4)),
      static_cast<float>(deg2rad(0.4)), static_cast<float>(deg2rad(1.2))};
  ASSERT_EQ(layers.size(), 4u);
  size_t i = 0;
  for (float layer : layers) EXPECT_NEAR(layer, expected_layers[i++], 1e-6);
  EXPECT_NEAR(scan.beams.front().elevation, deg2rad(-42.5), 1e-6);
  EXPECT_NEAR(scan.beams.back().elevation, deg2rad(42.5), 1e-6);
  EXPECT_NEAR(scan.beams[4 * 170].elevation, 0.0, 1e-6);
}

TEST(LidarHead, MaxRangeComesFromConfigThenScenarioThenDefault) {
  EXPECT_DOUBLE_EQ(LidarHead(LidarConfig{}, 0.0).max_range(), kDefaultLidarMaxRange);
  EXPECT_DOUBLE_EQ(LidarHead(LidarConfig{}, 80.0).max_range(), 80.0);
  LidarConfig c;
  c.max_range = 40.0;
  EXPECT_DOUBLE_EQ(LidarHead(c, 80.0).max_range(), 40.0);
  LidarHead head(c, 80.0);
  EXPECT_DOUBLE_EQ(head.scan(0, level_at(kAt10m), world::World()).max_range, 40.0);
}

TEST(LidarHead, LevelVehicleFacingAWallMeasuresItsDistance) {
  LidarHead head(exact_config(), 0.0);
  const LidarScan scan = head.scan(0, level_at(kAt10m), wall_world(20.0));
  ASSERT_EQ(static_cast<int>(scan.beams.size()), head.beams_per_scan());
  for (const auto& b : scan.beams) {
    ASSERT_EQ(b.status, kLidarOk);
    EXPECT_EQ(b.truth_id, kWallId);
    const double expected = 20.0 / (std::cos(b.elevation) * std::cos(b.layer_angle));
    EXPECT_NEAR(b.range, expected, 1e-4);
  }
}

TEST(LidarHead, MountOffsetAndAttitudeMoveTheBeams) {
  LidarConfig c = exact_config();
  c.mount_offset = Vec3(2.0, 0, 0.5);  // 2 m forward of the reference point
  LidarHead forward(c, 0.0);
  const LidarBeam centre = forward.scan(0, level_at(kAt10m), wall_world(20.0)).beams[4 * 170 + 2];
  ASSERT_NEAR(centre.elevation, 0.0, 1e-6);
  EXPECT_NEAR(centre.range, 18.0 / std::cos(centre.layer_angle), 1e-4);

  // Yawed 90 deg right on the airframe, the head looks east, past the wall.
  c.mount_offset = Vec3::Zero();
  c.mount_rpy = Vec3(0, 0, deg2rad(90));
  LidarHead sideways(c, 0.0);
  const LidarScan scan = sideways.scan(0, level_at(kAt10m), wall_world(20.0));
  ASSERT_EQ(static_cast<int>(scan.beams.size()), sideways.beams_per_scan());
  for (const auto& b : scan.beams) EXPECT_EQ(b.status, kLidarMaxRange);
}

TEST(LidarHead, OpenSkyGivesMaxRangeAndTheGroundIsMeasured) {
  LidarHead head(exact_config(), 0.0);
  const world::World ground_only({}, 0.0);
  const LidarScan scan = head.scan(0, level_at(kAt10m), ground_only);
  int sky = 0, ground = 0;
  for (const auto& b : scan.beams) {
    if (b.elevation >= 0) {
      EXPECT_EQ(b.status, kLidarMaxRange);
      EXPECT_FLOAT_EQ(b.range, static_cast<float>(kDefaultLidarMaxRange));
      EXPECT_EQ(b.truth_id, -1);
      ++sky;
    } else if (b.elevation < deg2rad(-20)) {
      ASSERT_EQ(b.status, kLidarOk);
      EXPECT_EQ(b.truth_id, 0);
      EXPECT_NEAR(b.range, 10.0 / (std::sin(-b.elevation) * std::cos(b.layer_angle)), 1e-4);
      ++ground;
    }
  }
  EXPECT_GT(sky, 600);
  EXPECT_GT(ground, 300);
}

TEST(LidarHead, DropoutProbabilityOneLosesEveryReturn) {
  LidarConfig c = exact_config();
  c.dropout_probability = 1.0;
  LidarHead head(c, 0.0);
  const LidarScan scan = head.scan(0, level_at(kAt10m), wall_world());
  ASSERT_EQ(static_cast<int>(scan.beams.size()), head.beams_per_scan());
  for (const auto& b : scan.beams) EXPECT_EQ(b.status, kLidarNoReturn);
}

TEST(LidarHead, SomeReturnsDropOutAtTheDefaultProbability) {
  LidarConfig c = exact_config();
  c.dropout_probability = 0.1;
  LidarHead head(c, 0.0);
  int dropped = 0;
  const LidarScan scan = head.scan(0, level_at(kAt10m), wall_world());
  for (const auto& b : scan.beams) dropped += b.status == kLidarNoReturn;
  EXPECT_GT(dropped, 70);  // 136 expected of 1364
  EXPECT_LT(dropped, 220);
}

TEST(LidarHead, NearFieldReturnsAreSaturated) {
  LidarHead head(exact_config(), 0.0);
  // 0.7 m from the wall: every beam's return is inside the 1 m saturation range.
  const LidarScan scan = head.scan(0, level_at(kAt10m), wall_world(0.7));
  ASSERT_EQ(static_cast<int>(scan.beams.size()), head.beams_per_scan());
  for (const auto& b : scan.beams) {
    EXPECT_EQ(b.status, kLidarSaturated);
    EXPECT_EQ(b.truth_id, kWallId);
  }
}

TEST(LidarHead, SaturationFaultHoldsTheLastRangeOfTheLayer) {
  LidarConfig c = exact_config();
  c.saturation_probability = 1.0;
  LidarHead head(c, 0.0);
  const LidarScan scan = head.scan(0, level_at(kAt10m), world::World({}, 0.0));
  // Scanning up from the ground into the sky: every beam without a return
  // repeats the last ground range of its layer, so its points stack above it.
  std::vector<float> last_ok(4, -1.0f);
  int held = 0;
  for (size_t i = 0; i < scan.beams.size(); ++i) {
    const LidarBeam& b = scan.beams[i];
    const size_t layer = i % 4;
    if (b.truth_id == -1) {
      ASSERT_EQ(b.status, kLidarSaturated);
      ASSERT_GT(last_ok[layer], 0.0f);
      EXPECT_EQ(b.range, last_ok[layer]);
      ++held;
    } else {
      ASSERT_EQ(b.status, kLidarOk);
      last_ok[layer] = b.range;
    }
  }
  EXPECT_GT(held, 600);
}

TEST(LidarHead, OutliersAreOkReturnsAtRandomRanges) {
  LidarConfig c = exact_config();
  c.outlier_probability = 1.0;
  LidarHead head(c, 0.0);
  const LidarScan scan = head.scan(0, level_at(kAt10m), wall_world(20.0));
  std::set<float> ranges;
  for (const auto& b : scan.beams) {
    ASSERT_EQ(b.status, kLidarOk);
    EXPECT_GE(b.range, c.min_range);
    EXPECT_LT(b.range, kDefaultLidarMaxRange);
    ranges.insert(b.range);
  }
  EXPECT_GT(ranges.size(), 1000u);
}

TEST(LidarHead, BeamTimesSpreadOverThePeriodAndEachStepUsesItsOwnPose) {
  LidarHead head(exact_config(), 0.0);
  std::vector<Utime> asked;
  const Utime t0 = 5'000'000;
  const LidarScan scan = head.scan(
      t0,
      [&](Utime t) {
        asked.push_back(t);
        return std::make_pair(kAt10m, Quat::Identity());
      },
      wall_world());
  EXPECT_EQ(scan.utime, t0);
  ASSERT_EQ(static_cast<int>(asked.size()), head.elevation_steps());
  const Utime period = 80'000;  // 12.5 Hz
  for (int step = 0; step < head.elevation_steps(); ++step) {
    const Utime expected = static_cast<Utime>(step) * period / head.elevation_steps();
    EXPECT_EQ(asked[step], t0 + expected);
    for (int layer = 0; layer < 4; ++layer) EXPECT_EQ(scan.beams[4 * step + layer].dt_us, expected);
  }
  EXPECT_EQ(scan.beams.front().dt_us, 0);
  EXPECT_GT(scan.beams.back().dt_us, period * 99 / 100);
  EXPECT_LT(scan.beams.back().dt_us, period);
}

TEST(LidarHead, AYawingVehicleSeesTheWallThroughItsChangingHeading) {
  LidarHead head(exact_config(), 0.0);
  const double yaw_rate = 1.0;  // rad/s: 4.6 deg over one scan
  const auto yawing = [&](Utime t) {
    return std::make_pair(kAt10m, quat_from_euler(0, 0, yaw_rate * to_seconds(t)));
  };
  const LidarScan moving = head.scan(0, yawing, wall_world(20.0));
  const LidarScan still = head.scan(0, level_at(kAt10m), wall_world(20.0));
  int differ = 0;
  for (size_t i = 0; i < moving.beams.size(); ++i) {
    const LidarBeam& b = moving.beams[i];
    const double yaw = yaw_rate * b.dt_us * 1e-6;
    const Vec3 d = beam_direction_sensor(b.elevation, b.layer_angle);
    const double north = std::cos(yaw) * d.x() - std::sin(yaw) * d.y();
    ASSERT_EQ(b.status, kLidarOk);
    EXPECT_NEAR(b.range, 20.0 / north, 1e-4);
    differ += std::abs(b.range - still.beams[i].range) > 1e-3;
  }
  EXPECT_GT(differ, 1000);
}

TEST(LidarHead, SameSeedGivesIdenticalScansAndAnotherSeedDiffers) {
  LidarConfig c;  // default noise and dropout
  LidarHead a(c, 0.0), b(c, 0.0);
  c.seed = 2;
  LidarHead other(c, 0.0);
  const world::World w = wall_world();
  for (int k = 0; k < 3; ++k) {
    const LidarScan sa = a.scan(k * 80'000, level_at(kAt10m), w);
    const LidarScan sb = b.scan(k * 80'000, level_at(kAt10m), w);
    const LidarScan so = other.scan(k * 80'000, level_at(kAt10m), w);
    EXPECT_EQ(sa.scan_index, k);
    ASSERT_EQ(static_cast<int>(sa.beams.size()), a.beams_per_scan());
    int same_as_other = 0;
    for (size_t i = 0; i < sa.beams.size(); ++i) {
      EXPECT_EQ(sa.beams[i].range, sb.beams[i].range);
      EXPECT_EQ(sa.beams[i].status, sb.beams[i].status);
      same_as_other += sa.beams[i].range == so.beams[i].range;
    }
    EXPECT_LT(same_as_other, 100);
  }
}

TEST(LidarHead, AdvanceCastsEachBeamWithThePoseAtItsTime) {
  // Flying north at 5 m/s towards the wall, stepped like the physics (2.5 ms).
  const Vec3 start(0, 0, -10), velocity(5, 0, 0);
  const auto pose_at = [&](Utime t) {
    return std::make_pair(Vec3(start + velocity * to_seconds(t)), Quat::Identity());
  };
  LidarHead stepped(exact_config(), 0.0);
  const world::World w = wall_world(20.0);
  std::vector<LidarScan> scans;
  for (Utime t = 0; t <= 200'000; t += 2500) {
    const auto [p, q] = pose_at(t);
    stepped.advance(t, p, q, w);
    while (auto s = stepped.take_completed_scan()) scans.push_back(std::move(*s));
  }
  ASSERT_EQ(scans.size(), 2u);  // a third one is still being cast
  LidarHead reference(exact_config(), 0.0);
  for (int k = 0; k < 2; ++k) {
    EXPECT_EQ(scans[k].utime, k * 80'000);
    EXPECT_EQ(scans[k].scan_index, k);
    const LidarScan expected = reference.scan(k * 80'000, pose_at, w);
    ASSERT_EQ(scans[k].beams.size(), expected.beams.size());
    for (size_t i = 0; i < expected.beams.size(); ++i) {
      EXPECT_EQ(scans[k].beams[i].dt_us, expected.beams[i].dt_us);
      EXPECT_NEAR(scans[k].beams[i].range, expected.beams[i].range, 1e-4);
    }
  }
  // The wall came 0.4 m closer between the first beams of the two scans.
  EXPECT_NEAR(
      scans[0].beams[0].range - scans[1].beams[0].range,
      0.4 / (std::cos(scans[0].beams[0].elevation) * std::cos(scans[0].beams[0].layer_angle)),
      1e-4);
}

TEST(LidarHead, ScansStartOnWholePeriodsAndADisabledHeadIsSilent) {
  LidarHead head(exact_config(), 0.0);
  const world::World w = wall_world();
  for (Utime t = 30'000; t <= 300'000; t += 2500) head.advance(t, kAt10m, Quat::Identity(), w);
  const auto first = head.take_completed_scan();
  ASSERT_TRUE(first);
  EXPECT_EQ(first->utime, 80'000);

  LidarConfig off = exact_config();
  off.enabled = false;
  LidarHead silent(off, 0.0);
  for (Utime t = 0; t <= 300'000; t += 2500) silent.advance(t, kAt10m, Quat::Identity(), w);
  EXPECT_FALSE(silent.take_completed_scan());
}

// --- vehicle_sim config and bus ---------------------------------------------

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
  sim::Lockstep lockstep;
  auto reader = YamlReader::empty("(defaults)");
  VehicleSimConfig config = load_vehicle_sim_config(reader);
  config.lidar.range_noise_sigma = 0;
  config.lidar.dropout_probability = 0;
  VehicleSimService vehicle(lockstep.lcm(), lockstep.clock(), scenario, config);

  // A wall 20 m ahead of the held start position, as the injector would send it.
  Node injector("test_injector", lockstep.lcm(), lockstep.clock());
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
  Node recorder("test_recorder", lockstep.lcm(), lockstep.clock());
  std::vector<lidar_scan_t> scans;
  recorder.subscribe<lidar_scan_t>(channels::kLidarRaw,
                                   [&](const lidar_scan_t& m) { scans.push_back(m); });
  lockstep.add(vehicle.node());
  lockstep.add(injector);
  lockstep.add(recorder);
  lockstep.run(to_utime(2.0));

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
