// The simulated LIDAR head: beam layout and timing, ranges against known
// geometry, the status flags and fault injection, motion during a scan and
// determinism. Its config and LIDAR_RAW on the bus: vehicle_sim's service
// tests (test_vehicle_sim_service.cpp).

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <vector>

#include "ofn/common/scenario.hpp"
#include "ofn/vehicle_sim/lidar_head.hpp"

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

}  // namespace
}  // namespace ofn::vehicle
