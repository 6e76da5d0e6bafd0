// ScanProcessor: where each beam lands in the world, which beams are never
// allowed to become points (saturated, no return, impossible ranges,
// isolated spikes), free rays, and the scans it refuses.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <vector>

#include "ofn/sensor_interface/scan_processor.hpp"

namespace ofn::sensing {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr Utime kPosePeriod = 10000;  // 100 Hz

/// Constant velocity and yaw rate, fixed roll and pitch.
struct Motion {
  Vec3 p0 = Vec3(0, 0, -8);
  Vec3 velocity = Vec3::Zero();
  double yaw0 = 0, yaw_rate = 0, roll = 0, pitch = 0;

  Pose at(Utime t) const {
    Pose p;
    p.utime = t;
    p.position = p0 + velocity * to_seconds(t);
    p.velocity = velocity;
    p.attitude = quat_from_euler(roll, pitch, yaw0 + yaw_rate * to_seconds(t));
    return p;
  }
};

/// NAV_STATE-like samples at 100 Hz over [from, to].
PoseBuffer poses_for(const Motion& m, Utime from, Utime to) {
  PoseBuffer buffer(10.0, 0.03);
  for (Utime t = from; t <= to; t += kPosePeriod) buffer.insert(m.at(t));
  return buffer;
}

/// A 4-layer head scanning its elevation range step by step, every layer
/// fired at each step.
struct ScanLayout {
  int layers = 4;
  int steps = 340;
  double elevation_lo = deg2rad(-20);
  double elevation_hi = deg2rad(40);
  double layer_spacing = deg2rad(1.0);
  int32_t beam_dt_us = 50;
  double max_range = 60.0;

  int beams() const { return layers * steps; }
  double elevation(int step) const {
    return elevation_lo + (elevation_hi - elevation_lo) * step / (steps - 1);
  }
  double layer_angle(int layer) const { return (layer - 0.5 * (layers - 1)) * layer_spacing; }
};

/// A plane n.x = offset in the world, solid up to `top_altitude`.
struct Wall {
  Vec3 normal = Vec3::UnitX();
  double offset = 20.0;
  double top_altitude = kInf;

  double distance(const Vec3& p) const { return normal.dot(p) - offset; }
};

struct SyntheticScan {
  RawScan scan;
  std::vector<bool> over_the_top;  // beam would have hit the plane above the wall's top
};

/// Ray-casts every beam against the wall with the pose of its own firing time.
SyntheticScan scan_wall(const Wall& wall, const Motion& motion, const LidarMount& mount,
                        const ScanLayout& layout, Utime utime, int32_t index = 0) {
  SyntheticScan s;
  s.scan.utime = utime;
  s.scan.scan_index = index;
  s.scan.max_range = layout.max_range;
  for (int step = 0; step < layout.steps; ++step)
    for (int layer = 0; layer < layout.layers; ++layer) {
      RawBeam b;
      b.dt_us = static_cast<int32_t>(s.scan.beams.size()) * layout.beam_dt_us;
      b.elevation = layout.elevation(step);
      b.layer_angle = layout.layer_angle(layer);
      const Pose pose = motion.at(utime + b.dt_us);
      const Vec3 origin = mount.origin_world(pose.position, pose.attitude);
      const Vec3 dir = pose.attitude *
                       (mount.body_from_sensor * beam_direction_sensor(b.elevation, b.layer_angle));
      const double along = wall.normal.dot(dir);
      const double range = along > 1e-9 ? -wall.distance(origin) / along : kInf;
      const bool hits_plane = range > 0 && range < layout.max_range;
      const bool over = hits_plane && -(origin + dir * range).z() > wall.top_altitude;
      if (hits_plane && !over) {
        b.status = BeamStatus::kOk;
        b.range = range;
      } else {
        b.status = BeamStatus::kMaxRange;
        b.range = layout.max_range;
      }
      s.scan.beams.push_back(b);
      s.over_the_top.push_back(over);
    }
  return s;
}

int count_status(const RawScan& scan, BeamStatus status) {
  return static_cast<int>(std::count_if(scan.beams.begin(), scan.beams.end(),
                                        [&](const RawBeam& b) { return b.status == status; }));
}

/// Three beams of one layer at one range around `elevation` (neighbours keep
/// the middle one from looking like a spike); returns the middle beam's point.
Vec3 land(double elevation, double layer_angle, double range, const Pose& pose,
          const LidarMount& mount = {}) {
  ScanProcessorConfig config;
  config.mount = mount;
  ScanProcessor processor(config);
  RawScan scan;
  scan.utime = pose.utime;
  scan.max_range = 60;
  for (int k = -1; k <= 1; ++k) {
    RawBeam b;
    b.dt_us = 0;
    b.elevation = elevation + k * deg2rad(0.2);
    b.layer_angle = layer_angle;
    b.range = range;
    scan.beams.push_back(b);
  }
  PoseBuffer poses;
  Pose before = pose, after = pose;
  before.utime -= kPosePeriod;
  after.utime += kPosePeriod;
  poses.insert(before);
  poses.insert(after);
  const ScanResult r = processor.process(scan, poses);
  EXPECT_EQ(r.status, ScanStatus::kOk);
  EXPECT_EQ(r.scan.points.size(), 3u);
  return r.scan.points.size() == 3 ? r.scan.points[1] : Vec3::Constant(kNaN);
}

Pose still_pose(double roll, double pitch, double yaw) {
  Pose p;
  p.utime = kMicrosPerSecond;
  p.position = Vec3(10, 20, -30);
  p.attitude = quat_from_euler(roll, pitch, yaw);
  return p;
}

void expect_near(const Vec3& actual, const Vec3& expected) {
  EXPECT_LT((actual - expected).norm(), 1e-6)
      << "got " << actual.transpose() << ", expected " << expected.transpose();
}

TEST(ScanProcessor, LevelBeamsLandWhereTheyPoint) {
  const Pose level = still_pose(0, 0, 0);
  expect_near(land(0, 0, 15, level), Vec3(25, 20, -30));
  // Elevation is up: altitude grows.
  expect_near(land(deg2rad(30), 0, 10, level), Vec3(10 + 10 * std::cos(deg2rad(30)), 20, -30 - 5));
  // The layer angle tilts towards the right (east when facing north).
  expect_near(land(0, deg2rad(10), 15, level),
              Vec3(10 + 15 * std::cos(deg2rad(10)), 20 + 15 * std::sin(deg2rad(10)), -30));
}

TEST(ScanProcessor, BeamsFollowTheVehicleAttitude) {
  // Yawed to east: forward is east.
  expect_near(land(0, 0, 15, still_pose(0, 0, deg2rad(90))), Vec3(10, 35, -30));
  // Nose up 20 deg: a level beam climbs.
  expect_near(land(0, 0, 15, still_pose(0, deg2rad(20), 0)),
              Vec3(10 + 15 * std::cos(deg2rad(20)), 20, -30 - 15 * std::sin(deg2rad(20))));
  // Rolled right 90 deg: the scan plane lies flat and "up" points east.
  expect_near(land(deg2rad(90), 0, 15, still_pose(deg2rad(90), 0, 0)), Vec3(10, 35, -30));
}

TEST(ScanProcessor, BeamsStartAtTheMountAndFollowItsRotation) {
  LidarMount offset_mount;
  offset_mount.offset_body = Vec3(1.5, 0, 0.7);  // forward and below the body origin
  expect_near(land(0, 0, 15, still_pose(0, 0, deg2rad(90)), offset_mount),
              Vec3(10, 20 + 16.5, -30 + 0.7));
  LidarMount tilted_mount;
  tilted_mount.body_from_sensor = quat_from_euler(0, deg2rad(-10), 0);  // looking 10 deg down
  expect_near(land(0, 0, 15, still_pose(0, 0, 0), tilted_mount),
              Vec3(10 + 15 * std::cos(deg2rad(10)), 20, -30 + 15 * std::sin(deg2rad(10))));
}

TEST(ScanProcessor, EachBeamIsPlacedWithThePoseOfItsOwnTime) {
  // Fast forward flight and a brisk yaw against an oblique wall: over the
  // 68 ms scan the vehicle moves 0.7 m and turns 2.3 deg.
  Motion motion;
  motion.velocity = Vec3(10, 3, -0.5);
  motion.yaw_rate = deg2rad(35);
  motion.yaw0 = deg2rad(-10);
  motion.pitch = deg2rad(-6);
  Wall wall;
  wall.normal = Vec3(std::cos(deg2rad(35)), std::sin(deg2rad(35)), 0);
  wall.offset = 25;
  LidarMount mount;
  mount.offset_body = Vec3(1.0, 0.2, 0.5);
  const ScanLayout layout;
  const Utime t0 = 1003700;  // between NAV_STATE samples
  const SyntheticScan s = scan_wall(wall, motion, mount, layout, t0);
  const int returns = count_status(s.scan, BeamStatus::kOk);
  ASSERT_GT(returns, 1000);

  ScanProcessorConfig config;
  config.mount = mount;
  ScanProcessor processor(config);
  const PoseBuffer poses = poses_for(motion, 0, 2 * kMicrosPerSecond);
  const ScanResult r = processor.process(s.scan, poses);
  ASSERT_EQ(r.status, ScanStatus::kOk);
  ASSERT_EQ(static_cast<int>(r.scan.points.size()), returns);  // a flat wall loses nothing
  for (const Vec3& p : r.scan.points) ASSERT_LT(std::abs(wall.distance(p)), 0.05) << p.transpose();

  // One pose for the whole scan would smear the wall by decimetres.
  const Pose mid = *poses.interpolate(t0 + layout.beams() * layout.beam_dt_us / 2);
  double worst = 0;
  for (const RawBeam& b : s.scan.beams)
    if (b.status == BeamStatus::kOk)
      worst =
          std::max(worst, std::abs(wall.distance(mount.to_world(
                              mid.position, mid.attitude, b.elevation, b.layer_angle, b.range))));
  EXPECT_GT(worst, 0.2);

  // The origin is the sensor's position at the scan's middle.
  const Pose truth = motion.at(t0 + (layout.beams() - 1) * layout.beam_dt_us / 2);
  EXPECT_LT((r.scan.sensor_origin - mount.origin_world(truth.position, truth.attitude)).norm(),
            1e-3);
  EXPECT_EQ(r.scan.utime, t0);
}

TEST(ScanProcessor, SaturatedBeamsNeverBecomePointsAboveTheWall) {
  // Bench3: above the wall's top the saturated receiver keeps reporting the
  // range of the last wall return, which would make the wall read taller.
  Motion motion;
  motion.p0 = Vec3(0, 0, -8);
  motion.velocity = Vec3(3, 0, 0);
  Wall wall;
  wall.offset = 20;
  wall.top_altitude = 12;
  const ScanLayout layout;
  SyntheticScan s = scan_wall(wall, motion, LidarMount{}, layout, kMicrosPerSecond);
  std::vector<double> held(layout.layers, kNaN);
  int saturated = 0;
  for (size_t i = 0; i < s.scan.beams.size(); ++i) {
    RawBeam& b = s.scan.beams[i];
    const size_t layer = i % layout.layers;
    if (b.status == BeamStatus::kOk) held[layer] = b.range;
    if (s.over_the_top[i]) {
      b.status = BeamStatus::kSaturated;
      b.range = held[layer];
      ++saturated;
    }
  }
  ASSERT_GT(saturated, 100);
  // A few saturated beams carry nothing usable at all.
  for (size_t i = s.scan.beams.size() - 4; i < s.scan.beams.size(); ++i) {
    s.scan.beams[i].status = BeamStatus::kSaturated;
    s.scan.beams[i].range = i % 2 ? kNaN : 0.0;
  }
  const int wall_returns = count_status(s.scan, BeamStatus::kOk);
  saturated = count_status(s.scan, BeamStatus::kSaturated);

  // The test is only meaningful if the held ranges would paint above the top.
  const PoseBuffer poses = poses_for(motion, 0, 2 * kMicrosPerSecond);
  double painted_top = 0;
  for (const RawBeam& b : s.scan.beams)
    if (b.status == BeamStatus::kSaturated && std::isfinite(b.range) && b.range > 1) {
      const Pose p = *poses.interpolate(s.scan.utime + b.dt_us);
      painted_top = std::max(
          painted_top,
          -LidarMount{}.to_world(p.position, p.attitude, b.elevation, b.layer_angle, b.range).z());
    }
  ASSERT_GT(painted_top, wall.top_altitude + 3);

  ScanProcessor processor;
  const ScanResult r = processor.process(s.scan, poses);
  ASSERT_EQ(r.status, ScanStatus::kOk);
  EXPECT_EQ(r.scan.counters.saturated, saturated);
  EXPECT_EQ(static_cast<int>(r.scan.points.size()), wall_returns);
  // Nor free space: a saturated receiver saw something, just not where.
  const int max_range = count_status(s.scan, BeamStatus::kMaxRange);
  EXPECT_EQ(r.scan.counters.max_range, max_range);
  EXPECT_EQ(static_cast<int>(r.scan.free_ray_ends.size()), (max_range + 1) / 2);
  double top = -kInf;
  for (const Vec3& p : r.scan.points) top = std::max(top, -p.z());
  EXPECT_LE(top, wall.top_altitude + 0.01);
  EXPECT_GT(top, wall.top_altitude - 0.5);  // the real top is still seen
}

TEST(ScanProcessor, NoReturnAndImpossibleRangesAreRejected) {
  const ScanLayout layout;
  const Motion motion;
  Wall wall;
  SyntheticScan s = scan_wall(wall, motion, LidarMount{}, layout, kMicrosPerSecond);
  const int wall_returns = count_status(s.scan, BeamStatus::kOk);
  // Scattered over the wall, each well inside it.
  const std::vector<std::pair<size_t, double>> bad_ok = {
      {401, kNaN}, {523, -3.0}, {647, 0.2}, {771, kInf}, {809, 0.0}};
  const std::vector<size_t> no_return = {433, 555, 677};
  for (const auto& [i, range] : bad_ok) {
    ASSERT_EQ(s.scan.beams[i].status, BeamStatus::kOk) << i;
    s.scan.beams[i].range = range;
  }
  for (size_t i : no_return) {
    ASSERT_EQ(s.scan.beams[i].status, BeamStatus::kOk) << i;
    s.scan.beams[i].status = BeamStatus::kNoReturn;  // its range (the wall's) must be ignored
  }
  ScanProcessor processor;
  const ScanResult r = processor.process(s.scan, poses_for(motion, 0, 2 * kMicrosPerSecond));
  ASSERT_EQ(r.status, ScanStatus::kOk);
  EXPECT_EQ(r.scan.counters.invalid_range, static_cast<int>(bad_ok.size()));
  EXPECT_EQ(r.scan.counters.no_return, static_cast<int>(no_return.size()));
  EXPECT_EQ(r.scan.counters.spikes, 0);
  EXPECT_EQ(r.scan.counters.rejected(), static_cast<int>(bad_ok.size() + no_return.size()));
  EXPECT_EQ(r.scan.points.size(),
            static_cast<size_t>(wall_returns) - bad_ok.size() - no_return.size());
  for (const Vec3& p : r.scan.points) {
    ASSERT_TRUE(p.allFinite());
    EXPECT_LT(std::abs(wall.distance(p)), 1e-6);
  }
}

TEST(ScanProcessor, MaxRangeBeamsBecomeFreeRaysAtTheStride) {
  const ScanLayout layout;
  Motion motion;
  Wall wall;
  wall.offset = 20;
  wall.top_altitude = 12;
  SyntheticScan s = scan_wall(wall, motion, LidarMount{}, layout, kMicrosPerSecond);
  // The head reports some beams as OK at the range limit: free space too.
  int at_limit = 0;
  for (RawBeam& b : s.scan.beams)
    if (b.status == BeamStatus::kMaxRange && (at_limit++ % 5 == 0)) {
      b.status = BeamStatus::kOk;
      b.range = 0.996 * layout.max_range;
    }
  const int max_range =
      layout.beams() - count_status(s.scan, BeamStatus::kOk) + at_limit / 5 + (at_limit % 5 != 0);
  const PoseBuffer poses = poses_for(motion, 0, 2 * kMicrosPerSecond);
  const int wall_points = layout.beams() - max_range;
  ASSERT_GT(max_range, 100);

  for (int stride : {1, 2, 3}) {
    ScanProcessorConfig config;
    config.free_ray_stride = stride;
    ScanProcessor processor(config);
    const ScanResult r = processor.process(s.scan, poses);
    ASSERT_EQ(r.status, ScanStatus::kOk);
    EXPECT_EQ(r.scan.counters.max_range, max_range);
    EXPECT_EQ(r.scan.counters.rejected(), 0);  // free space is information, not a rejection
    EXPECT_EQ(static_cast<int>(r.scan.points.size()), wall_points);
    EXPECT_EQ(static_cast<int>(r.scan.free_ray_ends.size()), (max_range + stride - 1) / stride)
        << "stride " << stride;
    for (const Vec3& end : r.scan.free_ray_ends)
      EXPECT_NEAR((end - motion.p0).norm(), layout.max_range, 1e-6);  // hovering: fixed origin
  }
}

TEST(ScanProcessor, IsolatedSpikesAreRemovedAndAFlatWallKeepsEveryPoint) {
  const ScanLayout layout;
  const Motion motion;
  Wall wall;
  wall.offset = 20;
  wall.top_altitude = 12;
  SyntheticScan s = scan_wall(wall, motion, LidarMount{}, layout, kMicrosPerSecond);
  const PoseBuffer poses = poses_for(motion, 0, 2 * kMicrosPerSecond);
  const int wall_returns = count_status(s.scan, BeamStatus::kOk);
  {
    ScanProcessor processor;
    const ScanResult clean = processor.process(s.scan, poses);
    ASSERT_EQ(clean.status, ScanStatus::kOk);
    EXPECT_EQ(clean.scan.counters.spikes, 0);
    EXPECT_EQ(static_cast<int>(clean.scan.points.size()), wall_returns);  // edges included
  }
  // A return in the empty sky above the wall, and one 15 m in front of it.
  const size_t sky = s.scan.beams.size() - 40, front = 402;
  ASSERT_EQ(s.scan.beams[sky].status, BeamStatus::kMaxRange);
  ASSERT_EQ(s.scan.beams[front].status, BeamStatus::kOk);
  s.scan.beams[sky] = RawBeam{s.scan.beams[sky].dt_us, s.scan.beams[sky].elevation,
                              s.scan.beams[sky].layer_angle, 25.0, BeamStatus::kOk};
  s.scan.beams[front].range = 5.0;
  ScanProcessor processor;
  const ScanResult r = processor.process(s.scan, poses);
  ASSERT_EQ(r.status, ScanStatus::kOk);
  EXPECT_EQ(r.scan.counters.spikes, 2);
  EXPECT_EQ(static_cast<int>(r.scan.points.size()), wall_returns - 1);
  for (const Vec3& p : r.scan.points) EXPECT_LT(std::abs(wall.distance(p)), 1e-6);
}

TEST(ScanProcessor, RemovesMostRandomOutliers) {
  const ScanLayout layout;
  Motion motion;
  motion.velocity = Vec3(4, 0, 0);
  Wall wall;
  wall.offset = 30;
  const PoseBuffer poses = poses_for(motion, 0, 4 * kMicrosPerSecond);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> any_range(1.0, 55.0);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  ScanProcessor processor;
  int outliers = 0, surviving_outliers = 0, wall_returns = 0, wall_points = 0;
  for (int k = 0; k < 20; ++k) {
    const Utime t0 = kMicrosPerSecond + k * 100000;
    SyntheticScan s = scan_wall(wall, motion, LidarMount{}, layout, t0, k);
    for (RawBeam& b : s.scan.beams) {
      if (b.status != BeamStatus::kOk) continue;
      if (unit(rng) < 0.01) {
        double r;
        do r = any_range(rng);
        while (std::abs(r - b.range) < 2.0);  // a real outlier: off the wall
        b.range = r;
        ++outliers;
      } else {
        ++wall_returns;
      }
    }
    const ScanResult r = processor.process(s.scan, poses);
    ASSERT_EQ(r.status, ScanStatus::kOk);
    for (const Vec3& p : r.scan.points)
      (std::abs(wall.distance(p)) < 0.01 ? wall_points : surviving_outliers)++;
  }
  ASSERT_GT(outliers, 100);
  EXPECT_GE(outliers - surviving_outliers, 0.9 * outliers)
      << surviving_outliers << " of " << outliers << " outliers survived";
  EXPECT_GE(wall_points, 0.995 * wall_returns);
}

TEST(ScanProcessor, DropsTheWholeScanWhenAnyBeamHasNoPose) {
  const ScanLayout layout;  // 68 ms per scan
  const Motion motion;
  const PoseBuffer poses = poses_for(motion, kMicrosPerSecond, 2 * kMicrosPerSecond);
  ScanProcessor processor;
  auto status_at = [&](Utime t0) {
    return processor.process(scan_wall(Wall{}, motion, LidarMount{}, layout, t0).scan, poses);
  };
  // Starts before the oldest pose, ends after the newest beyond extrapolation,
  // lies wholly in the future.
  EXPECT_EQ(status_at(kMicrosPerSecond - 1000).status, ScanStatus::kNoPose);
  EXPECT_EQ(status_at(2 * kMicrosPerSecond - 20000).status, ScanStatus::kNoPose);
  const ScanResult future = status_at(3 * kMicrosPerSecond);
  EXPECT_EQ(future.status, ScanStatus::kNoPose);
  EXPECT_TRUE(future.scan.points.empty());
  EXPECT_FALSE(processor.last_scan_utime());
  // Up to 30 ms of extrapolation is covered; an earlier scan is still welcome.
  EXPECT_EQ(status_at(2 * kMicrosPerSecond - 90000).status, ScanStatus::kOk);
  EXPECT_EQ(status_at(2 * kMicrosPerSecond - 50000).status, ScanStatus::kOk);  // ends 18 ms late
}

TEST(ScanProcessor, RefusesScansNotNewerThanTheLastOne) {
  const ScanLayout layout;
  const Motion motion;
  const PoseBuffer poses = poses_for(motion, 0, 2 * kMicrosPerSecond);
  const RawScan scan = scan_wall(Wall{}, motion, LidarMount{}, layout, kMicrosPerSecond).scan;
  ScanProcessor processor;
  ASSERT_EQ(processor.process(scan, poses).status, ScanStatus::kOk);
  EXPECT_EQ(processor.process(scan, poses).status, ScanStatus::kOutOfOrder);
  RawScan older = scan;
  older.utime -= 1;
  EXPECT_EQ(processor.process(older, poses).status, ScanStatus::kOutOfOrder);
  RawScan newer = scan;
  newer.utime += 1;
  EXPECT_EQ(processor.process(newer, poses).status, ScanStatus::kOk);
  EXPECT_EQ(processor.last_scan_utime(), newer.utime);
}

TEST(ScanProcessor, RejectsNonsenseSettings) {
  ScanProcessorConfig stride;
  stride.free_ray_stride = 0;
  EXPECT_THROW(ScanProcessor{stride}, std::invalid_argument);
  ScanProcessorConfig fraction;
  fraction.max_range_fraction = 1.5;
  EXPECT_THROW(ScanProcessor{fraction}, std::invalid_argument);
}

}  // namespace
}  // namespace ofn::sensing
