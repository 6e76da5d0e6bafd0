// The sensor interface on an in-process bus with a manual clock: scans wait
// for navigation to cover them, come out in the world frame, and bad or
// unplaceable scans are counted and dropped without stopping the service.

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>
#include <lcm/lcm-cpp.hpp>

#include "ofn/common/channels.hpp"
#include "ofn/common/config.hpp"
#include "ofn/common/logging.hpp"
#include "ofn/common/node.hpp"
#include "ofn/common/validate.hpp"
#include "ofn/sensor_interface/sensor_interface_service.hpp"

namespace ofn::sensing {
namespace {

constexpr Utime kStart = 10 * kMicrosPerSecond;
constexpr Utime kMs = 1000;
const Vec3 kStartPosition(5, 0, -30);
const Vec3 kVelocity(5, 1, 0);  // m/s, world NED
constexpr double kYaw = 0.3;    // rad

Vec3 position_at(Utime t) {
  return kStartPosition + kVelocity * to_seconds(t - kStart);
}

SensorInterfaceConfig default_config() {
  auto reader = YamlReader::empty("(defaults)");
  return load_sensor_interface_config(reader);
}

/// A small head (2 layers x 20 steps, 100 us apart) looking at a sphere of
/// radius 20 m around the sensor: every beam returns at the same range.
lidar_scan_t sphere_scan(Utime utime, int32_t index, double range = 20.0) {
  lidar_scan_t m{};
  m.utime = utime;
  m.scan_index = index;
  m.max_range = 60;
  for (int step = 0; step < 20; ++step)
    for (int layer = 0; layer < 2; ++layer) {
      m.beam_dt_us.push_back(static_cast<int32_t>(m.beam_dt_us.size()) * 100);
      m.elevation.push_back(static_cast<float>(deg2rad(-10.0 + step)));
      m.layer_angle.push_back(static_cast<float>(deg2rad(layer - 0.5)));
      m.range.push_back(static_cast<float>(range));
      m.status.push_back(lidar_scan_t::OK);
    }
  m.num_beams = static_cast<int32_t>(m.range.size());
  return m;
}

class SensorInterfaceServiceTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { set_log_level("error"); }
  static void TearDownTestSuite() { set_log_level("info"); }

  explicit SensorInterfaceServiceTest(SensorInterfaceConfig config = default_config())
      : lcm_("memq://"), clock_(kStart), service_(lcm_, clock_, config), bus_("bus", lcm_, clock_) {
    bus_.subscribe<scan_world_t>(channels::kScanWorld,
                                 [this](const scan_world_t& m) { published_.push_back(m); });
    bus_.subscribe<scanner_status_t>(channels::kScannerStatus, [this](const scanner_status_t& m) {
      scanner_status_.push_back(m);
    });
  }

  void deliver() {
    while (lcm_.handleTimeout(0) > 0) {
    }
  }
  /// Moves clock time on, running the service's timers on the way.
  void advance_to(Utime t) {
    for (Utime next = service_.node().next_deadline(); next <= t;
         next = service_.node().next_deadline()) {
      clock_.set(std::max(clock_.now(), next));
      service_.node().fire_due_timers();
      deliver();
    }
    clock_.set(t);
    deliver();
  }
  void publish_nav(Utime t) {
    nav_state_t m{};
    m.utime = t;
    m.frame = "NED";
    const Vec3 p = position_at(t);
    for (int i = 0; i < 3; ++i) {
      m.position[i] = p[i];
      m.velocity[i] = kVelocity[i];
    }
    const Quat q = quat_from_euler(0, 0, kYaw);
    m.quaternion[0] = q.w();
    m.quaternion[1] = q.x();
    m.quaternion[2] = q.y();
    m.quaternion[3] = q.z();
    m.euler[2] = kYaw;
    bus_.publish(channels::kNavState, m);
    deliver();
  }
  /// NAV_STATE at 100 Hz over [from, to], the clock following it.
  void fly(Utime from, Utime to) {
    for (Utime t = from; t <= to; t += 10 * kMs) {
      advance_to(std::max(clock_.now(), t));
      publish_nav(t);
    }
  }
  void publish_scan(const lidar_scan_t& m) {
    bus_.publish(channels::kLidarRaw, m);
    deliver();
  }

  lcm::LCM lcm_;
  ManualClock clock_;
  SensorInterfaceService service_;
  Node bus_;
  std::vector<scan_world_t> published_;
  std::vector<scanner_status_t> scanner_status_;
};

TEST_F(SensorInterfaceServiceTest, ScanWaitsForNavigationThenComesOutInTheWorldFrame) {
  ASSERT_TRUE(lcm_.good());
  fly(kStart, kStart + 20 * kMs);
  const lidar_scan_t raw = sphere_scan(kStart + 22 * kMs, 7);  // last beam at +25.9 ms
  advance_to(kStart + 26 * kMs);
  publish_scan(raw);
  EXPECT_TRUE(published_.empty());  // navigation does not reach its beams yet
  EXPECT_EQ(service_.queued_scans(), 1u);

  fly(kStart + 30 * kMs, kStart + 30 * kMs);
  ASSERT_EQ(published_.size(), 1u);
  const scan_world_t& out = published_[0];
  EXPECT_EQ(validate(out), "");
  EXPECT_EQ(out.frame, "NED");
  EXPECT_EQ(out.utime, raw.utime);
  EXPECT_EQ(out.scan_index, 7);
  EXPECT_EQ(out.num_rejected, 0);
  EXPECT_EQ(out.num_free_rays, 0);
  ASSERT_EQ(out.num_points, raw.num_beams);
  // Every beam placed with the vehicle's position at its own firing time.
  const Quat attitude = quat_from_euler(0, 0, kYaw);
  for (int i = 0; i < raw.num_beams; ++i) {
    const Vec3 expected = position_at(raw.utime + raw.beam_dt_us[i]) +
                          attitude * beam_direction_sensor(raw.elevation[i], raw.layer_angle[i]) *
                              static_cast<double>(raw.range[i]);
    const Vec3 got(out.points[i][0], out.points[i][1], out.points[i][2]);
    EXPECT_LT((got - expected).norm(), 1e-4) << "beam " << i;
  }
  const Vec3 origin(out.sensor_origin[0], out.sensor_origin[1], out.sensor_origin[2]);
  EXPECT_LT((origin - position_at(raw.utime + raw.beam_dt_us.back() / 2)).norm(), 1e-6);
  EXPECT_EQ(service_.counters().scans_published, 1);
  EXPECT_EQ(service_.queued_scans(), 0u);
  EXPECT_EQ(service_.node().counters().rejected, 0);
}

TEST_F(SensorInterfaceServiceTest, ScanWithoutNavigationIsDroppedAfterPoseWait) {
  fly(kStart, kStart + 50 * kMs);
  advance_to(kStart + 60 * kMs);
  publish_scan(sphere_scan(kStart + 55 * kMs, 1));  // navigation stops before it
  advance_to(kStart + 300 * kMs);
  EXPECT_EQ(service_.queued_scans(), 1u);  // still waiting, 0.24 s in
  EXPECT_EQ(service_.counters().dropped_no_pose, 0);
  advance_to(kStart + 400 * kMs);
  EXPECT_EQ(service_.queued_scans(), 0u);
  EXPECT_EQ(service_.counters().dropped_no_pose, 1);
  EXPECT_GE(service_.node().counters().rejected, 1);
  EXPECT_TRUE(published_.empty());

  // Navigation returns: the next scan goes through.
  fly(kStart + 410 * kMs, kStart + 430 * kMs);
  publish_scan(sphere_scan(kStart + 415 * kMs, 2));
  ASSERT_EQ(published_.size(), 1u);
  EXPECT_EQ(published_[0].scan_index, 2);
}

// The controller sweeps the scanner only while scans arrive: each accepted
// scan says so at once, before it waits for navigation, whatever becomes of
// it; a scan refused (out of order, or invalid) does not.
TEST_F(SensorInterfaceServiceTest, EveryAcceptedScanSaysTheScannerScans) {
  lidar_scan_t scan = sphere_scan(kStart + 20 * kMs, 7);
  scan.status[3] = lidar_scan_t::NO_RETURN;
  scan.status[5] = lidar_scan_t::MAX_RANGE;
  publish_scan(scan);  // no navigation yet: the scan waits, the status does not
  ASSERT_EQ(scanner_status_.size(), 1u);
  EXPECT_TRUE(published_.empty());
  EXPECT_EQ(scanner_status_[0].utime, scan.utime);
  EXPECT_EQ(scanner_status_[0].scan_index, 7);
  EXPECT_EQ(scanner_status_[0].beams, 40);
  EXPECT_EQ(scanner_status_[0].returns, 38);

  publish_scan(sphere_scan(kStart + 10 * kMs, 8));  // older than the last: refused
  lidar_scan_t bad = sphere_scan(kStart + 30 * kMs, 9);
  bad.max_range = -1;  // invalid: refused
  publish_scan(bad);
  EXPECT_EQ(scanner_status_.size(), 1u);
  publish_scan(sphere_scan(kStart + 40 * kMs, 10));
  ASSERT_EQ(scanner_status_.size(), 2u);
  EXPECT_EQ(scanner_status_[1].scan_index, 10);
}

TEST_F(SensorInterfaceServiceTest, ScanWithNoNavigationAtAllIsDroppedAfterPoseWait) {
  publish_scan(sphere_scan(kStart + 1 * kMs, 1));
  EXPECT_EQ(service_.queued_scans(), 1u);
  advance_to(kStart + 400 * kMs);
  EXPECT_EQ(service_.counters().dropped_no_pose, 1);
  EXPECT_EQ(service_.queued_scans(), 0u);
  EXPECT_TRUE(published_.empty());
}

TEST_F(SensorInterfaceServiceTest, WaitingQueueIsBounded) {
  fly(kStart, kStart + 10 * kMs);
  for (int i = 0; i < 12; ++i) publish_scan(sphere_scan(kStart + (20 + i) * kMs, i));
  EXPECT_EQ(service_.queued_scans(), 8u);
  EXPECT_EQ(service_.counters().dropped_no_pose, 4);  // the four oldest gave way
  fly(kStart + 20 * kMs, kStart + 40 * kMs);
  ASSERT_EQ(published_.size(), 8u);
  EXPECT_EQ(published_.front().scan_index, 4);
  EXPECT_EQ(published_.back().scan_index, 11);
}

TEST_F(SensorInterfaceServiceTest, BadInputIsRejectedAndAGoodScanStillComesOut) {
  fly(kStart, kStart + 100 * kMs);

  lidar_scan_t nan_range = sphere_scan(kStart + 10 * kMs, 1);
  nan_range.range[5] = std::numeric_limits<float>::quiet_NaN();
  publish_scan(nan_range);
  EXPECT_EQ(service_.node().counters().rejected, 1);

  lidar_scan_t oversized{};
  oversized.utime = kStart + 11 * kMs;
  oversized.max_range = 60;
  oversized.num_beams = MessageLimits::kMaxBeams + 1;
  oversized.beam_dt_us.assign(oversized.num_beams, 0);
  oversized.elevation.assign(oversized.num_beams, 0.f);
  oversized.layer_angle.assign(oversized.num_beams, 0.f);
  oversized.range.assign(oversized.num_beams, 10.f);
  oversized.status.assign(oversized.num_beams, lidar_scan_t::OK);
  publish_scan(oversized);
  EXPECT_EQ(service_.node().counters().rejected, 2);
  EXPECT_EQ(service_.counters().scans_received, 0);  // neither reached the service

  publish_scan(sphere_scan(kStart + 50 * kMs, 2));
  ASSERT_EQ(published_.size(), 1u);
  publish_scan(sphere_scan(kStart + 40 * kMs, 3));  // older than the last scan
  publish_scan(sphere_scan(kStart + 50 * kMs, 4));  // a duplicate
  EXPECT_EQ(service_.counters().dropped_out_of_order, 2);
  EXPECT_EQ(service_.node().counters().rejected, 4);
  EXPECT_EQ(published_.size(), 1u);

  publish_nav(kStart + 90 * kMs);  // navigation out of order
  EXPECT_EQ(service_.counters().nav_out_of_order, 1);
  EXPECT_EQ(service_.poses().newest()->utime, kStart + 100 * kMs);

  // A scan of nothing but unusable beams is still a scan: published empty.
  lidar_scan_t blind = sphere_scan(kStart + 60 * kMs, 5);
  for (size_t i = 0; i < blind.status.size(); ++i)
    blind.status[i] = i % 2 ? lidar_scan_t::NO_RETURN : lidar_scan_t::SATURATED;
  publish_scan(blind);
  ASSERT_EQ(published_.size(), 2u);
  EXPECT_EQ(published_[1].num_points, 0);
  EXPECT_EQ(published_[1].num_rejected, blind.num_beams);

  publish_scan(sphere_scan(kStart + 70 * kMs, 6));
  ASSERT_EQ(published_.size(), 3u);
  EXPECT_EQ(published_[2].scan_index, 6);
  EXPECT_EQ(published_[2].num_points, 40);
  EXPECT_EQ(service_.counters().scans_published, 3);
  EXPECT_EQ(service_.counters().beams.saturated, 20);
  EXPECT_EQ(service_.counters().beams.no_return, 20);
}

class SensorInterfaceShortHistoryTest : public SensorInterfaceServiceTest {
 protected:
  static SensorInterfaceConfig short_history() {
    SensorInterfaceConfig c = default_config();
    c.pose_history = 0.5;
    return c;
  }
  SensorInterfaceShortHistoryTest() : SensorInterfaceServiceTest(short_history()) {}
};

TEST_F(SensorInterfaceShortHistoryTest, ScanOlderThanThePosesIsDroppedAtOnce) {
  fly(kStart, kStart + 1000 * kMs);
  ASSERT_GT(service_.poses().oldest()->utime, kStart + 300 * kMs);
  publish_scan(sphere_scan(kStart + 300 * kMs, 1));  // 0.7 s old: within scan_max_age
  EXPECT_EQ(service_.counters().dropped_no_pose, 1);
  EXPECT_EQ(service_.queued_scans(), 0u);
  EXPECT_TRUE(published_.empty());
}

TEST(SensorInterfaceConfigFile, ShippedFileHoldsTheDefaults) {
  auto reader =
      YamlReader::load_file(std::string(OFN_SOURCE_DIR) + "/config/sensor_interface.yaml");
  const SensorInterfaceConfig file = load_sensor_interface_config(reader);
  const SensorInterfaceConfig defaults = default_config();
  EXPECT_EQ(file.pose_history, defaults.pose_history);
  EXPECT_EQ(file.max_extrapolation, defaults.max_extrapolation);
  EXPECT_EQ(file.pose_wait, defaults.pose_wait);
  EXPECT_EQ(file.max_queued_scans, defaults.max_queued_scans);
  EXPECT_EQ(file.nav_max_age, defaults.nav_max_age);
  EXPECT_EQ(file.scan_max_age, defaults.scan_max_age);
  const ScanProcessorConfig &f = file.processor, &d = defaults.processor;
  EXPECT_EQ(f.min_range, d.min_range);
  EXPECT_EQ(f.max_range_fraction, d.max_range_fraction);
  EXPECT_EQ(f.spike_distance, d.spike_distance);
  EXPECT_EQ(f.spike_range_factor, d.spike_range_factor);
  EXPECT_EQ(f.free_ray_stride, d.free_ray_stride);
  EXPECT_EQ(f.mount.offset_body, d.mount.offset_body);
  EXPECT_LT(f.mount.body_from_sensor.angularDistance(d.mount.body_from_sensor), 1e-12);
}

TEST(SensorInterfaceConfigFile, MountAnglesAreDegreesAndErrorsNameTheField) {
  YamlReader mount(YAML::Load("mount: {offset: [1.2, 0, 0.6], pitch_deg: -90}"), "test.yaml", "");
  const SensorInterfaceConfig c = load_sensor_interface_config(mount);
  EXPECT_EQ(c.processor.mount.offset_body, Vec3(1.2, 0, 0.6));
  // Pitched straight down: the sensor's x axis is the body's down.
  EXPECT_LT((c.processor.mount.body_from_sensor * Vec3::UnitX() - Vec3::UnitZ()).norm(), 1e-12);

  YamlReader typo(YAML::Load("filter: {min_rang: 1.0}"), "test.yaml", "");
  try {
    load_sensor_interface_config(typo);
    FAIL() << "a misspelt field was accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("filter.min_rang"), std::string::npos) << e.what();
  }
  YamlReader stride(YAML::Load("filter: {free_ray_stride: 0}"), "test.yaml", "");
  try {
    load_sensor_interface_config(stride);
    FAIL() << "a zero stride was accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("filter.free_ray_stride"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace ofn::sensing
