// The mapper service on the bus: scans become OBSTACLE_GRID at once and
// cuboids once a second; bad input is rejected, counted, and survived.

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include <yaml-cpp/yaml.h>
#include <lcm/lcm-cpp.hpp>

#include "ofn/common/channels.hpp"
#include "ofn/common/clock.hpp"
#include "ofn/common/logging.hpp"
#include "ofn/common/node.hpp"
#include "ofn/common/validate.hpp"
#include "ofn/mapper/mapper_service.hpp"
#include "service_test_bus.hpp"

namespace ofn::mapping {
namespace {

constexpr Utime kStart = 10 * kMicrosPerSecond;

/// A wall 30 m north of the vehicle, 10 m wide and 20 m tall, as points.
scan_world_t wall_scan(Utime utime) {
  scan_world_t m{};
  m.utime = utime;
  m.frame = "NED";
  m.sensor_origin[2] = -30;
  for (double e = -5; e <= 5; e += 0.25)
    for (double h = 0.5; h <= 20; h += 0.25)
      m.points.push_back({30.0f, static_cast<float>(e), static_cast<float>(-h)});
  // Beams that pass 3 m over the wall and on: its top was seen.
  for (double e = -5; e <= 5; e += 0.25)
    m.free_ray_ends.push_back({60.0f, static_cast<float>(e), -16.0f});
  m.num_points = static_cast<int32_t>(m.points.size());
  m.num_free_rays = static_cast<int32_t>(m.free_ray_ends.size());
  return m;
}

class MapperServiceTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { set_log_level("error"); }
  static void TearDownTestSuite() { set_log_level("info"); }

  MapperServiceTest()
      : bus_(kStart),
        service_(bus_.lcm(), bus_.clock(), config()),
        listener_("listener", bus_.lcm(), bus_.clock()) {
    listener_.subscribe<obstacle_grid_t>(channels::kObstacleGrid,
                                         [this](const obstacle_grid_t& m) { grids_.push_back(m); });
    listener_.subscribe<cuboid_list_t>(channels::kCuboids,
                                       [this](const cuboid_list_t& m) { cuboids_.push_back(m); });
  }
  static MapperServiceConfig config() {
    auto reader = YamlReader::empty("(defaults)");
    return load_mapper_config(reader);
  }
  void deliver() { bus_.deliver(); }
  void advance_to(Utime t) { bus_.advance_to(service_.node(), t); }
  template <class Msg>
  void send(const std::string& channel, const Msg& m) {
    bus_.send(channel, m);
  }
  /// A scan fed over several cycles until the wall is confirmed.
  void map_wall(Utime from, int scans) {
    for (int i = 0; i < scans; ++i) {
      const Utime t = from + i * 80000;
      advance_to(t);
      send(channels::kScanWorld, wall_scan(t));
    }
  }

  testing_support::ServiceTestBus bus_;
  MapperService service_;
  Node listener_;
  std::vector<obstacle_grid_t> grids_;
  std::vector<cuboid_list_t> cuboids_;
};

TEST_F(MapperServiceTest, ScansBecomeAGridAtOnceAndCuboidsEverySecond) {
  map_wall(kStart, 30);
  ASSERT_EQ(grids_.size(), 30u);
  const auto& g = grids_.back();
  EXPECT_TRUE(validate(g).empty());
  float top = 0;
  for (float v : g.top_altitude) top = std::max(top, v);
  EXPECT_NEAR(top, 20.0, 0.5);
  advance_to(kStart + 3 * kMicrosPerSecond);
  ASSERT_FALSE(cuboids_.empty());
  const auto& c = cuboids_.back();
  EXPECT_TRUE(validate(c).empty());
  ASSERT_EQ(c.num_cuboids, 1);
  EXPECT_TRUE(c.cuboids[0].top_observed);
  EXPECT_NEAR(-c.cuboids[0].min_corner[2], 20.0, 1.5);
  EXPECT_LE(c.cuboids[0].min_corner[0], 30.0);
  EXPECT_GE(c.cuboids[0].max_corner[0], 30.0);
}

TEST_F(MapperServiceTest, BadScansAreRejectedCountedAndTheMapperKeepsRunning) {
  map_wall(kStart, 5);
  const size_t grids_before = grids_.size();
  const int64_t rejected_before = service_.node().counters().rejected;

  scan_world_t nan_scan = wall_scan(bus_.now() + 1000);
  nan_scan.points[3][1] = std::numeric_limits<float>::quiet_NaN();
  send(channels::kScanWorld, nan_scan);

  scan_world_t old_scan = wall_scan(bus_.now() - 200000);  // older than the last one
  send(channels::kScanWorld, old_scan);

  scan_world_t huge = wall_scan(bus_.now() + 2000);
  huge.points.resize(MessageLimits::kMaxScanPoints + 1, {1.0f, 1.0f, -1.0f});
  huge.num_points = static_cast<int32_t>(huge.points.size());
  send(channels::kScanWorld, huge);

  scan_world_t wrong_frame = wall_scan(bus_.now() + 3000);
  wrong_frame.frame = "ENU";
  send(channels::kScanWorld, wrong_frame);

  scan_world_t stale = wall_scan(bus_.now() - 5 * kMicrosPerSecond);
  send(channels::kScanWorld, stale);

  EXPECT_EQ(grids_.size(), grids_before) << "a bad scan changed the map";
  EXPECT_EQ(service_.node().counters().rejected - rejected_before, 5);
  EXPECT_EQ(service_.scans_dropped_out_of_order(), 1);

  // A good scan afterwards is mapped as usual.
  advance_to(bus_.now() + 80000);
  send(channels::kScanWorld, wall_scan(bus_.now()));
  EXPECT_EQ(grids_.size(), grids_before + 1);
}

TEST(MapperConfig, DefaultsMatchTheShippedFileAndErrorsNameTheField) {
  auto shipped = YamlReader::load_file(std::string(OFN_SOURCE_DIR) + "/config/mapper.yaml");
  const auto c = load_mapper_config(shipped);
  auto empty = YamlReader::empty("(defaults)");
  const auto d = load_mapper_config(empty);
  EXPECT_EQ(c.mapper.grid.resolution, d.mapper.grid.resolution);
  EXPECT_EQ(c.mapper.grid.safety_margin, d.mapper.grid.safety_margin);
  EXPECT_EQ(c.mapper.occupancy.max_range, d.mapper.occupancy.max_range);
  EXPECT_EQ(c.mapper.cuboids.min_area, d.mapper.cuboids.min_area);
  EXPECT_EQ(c.mapper.database.retire_after_misses, d.mapper.database.retire_after_misses);

  YamlReader bad(YAML::Load("grid: {resolution: -1}"), "bad.yaml", "");
  try {
    load_mapper_config(bad);
    FAIL() << "a negative resolution was accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("resolution"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace ofn::mapping
