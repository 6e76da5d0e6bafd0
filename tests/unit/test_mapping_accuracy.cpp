// End-to-end accuracy of sensing and mapping on the benchmark courses: the
// simulated LIDAR head scans each course while the vehicle flies a path past
// its obstacles with the yaw sweep on; the sensor interface and the mapper
// turn the scans into cuboids, which are checked against the true obstacles.

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "ofn/common/frames.hpp"
#include "ofn/common/scenario.hpp"
#include "ofn/mapper/mapper.hpp"
#include "ofn/sensor_interface/pose_buffer.hpp"
#include "ofn/sensor_interface/scan_processor.hpp"
#include "ofn/vehicle_sim/lidar_head.hpp"
#include "ofn/world/world.hpp"

namespace ofn {
namespace {

constexpr double kFt = kMetresPerFoot;
constexpr double kSpeed = 10.0 * kFt;        // m/s, the courses' speed
constexpr double kSweepFrequency = 0.2;      // Hz
const double kSweepHalfAngle = deg2rad(20);  // 40 deg peak to peak

std::string scenario_path(const std::string& name) {
  return std::string(OFN_SOURCE_DIR) + "/sim/scenarios/" + name + ".yaml";
}

/// A polyline flown at constant speed, heading along each leg plus the yaw
/// sweep; level attitude (the mapper does not care about the small tilts).
class KinematicPath {
 public:
  explicit KinematicPath(const std::vector<Vec3>& course_points_ft) {
    for (const auto& p : course_points_ft) points_.push_back(course_to_ned(p * kFt));
    lengths_.push_back(0);
    for (size_t i = 1; i < points_.size(); ++i)
      lengths_.push_back(lengths_.back() + (points_[i] - points_[i - 1]).norm());
  }
  double duration() const { return lengths_.back() / kSpeed; }

  std::pair<Vec3, Quat> pose(Utime t_us) const {
    const double t = to_seconds(t_us);
    const double s = std::clamp(t * kSpeed, 0.0, lengths_.back());
    size_t i = 1;
    while (i + 1 < points_.size() && lengths_[i] < s) ++i;
    const Vec3 leg = points_[i] - points_[i - 1];
    const double f = (s - lengths_[i - 1]) / std::max(1e-9, leg.norm());
    const Vec3 position = points_[i - 1] + f * leg;
    const double heading = std::atan2(leg.y(), leg.x());
    const double yaw = heading + kSweepHalfAngle * std::sin(2 * kPi * kSweepFrequency * t);
    return {position, quat_from_euler(0, 0, yaw)};
  }

 private:
  std::vector<Vec3> points_;
  std::vector<double> lengths_;
};

/// Hand-made paths past each course's obstacles (course frame, ft), the way
/// the table of the benchmarks says the optimum goes, at 20+ ft clearance.
std::vector<Vec3> course_path(const std::string& name) {
  if (name == "bench1")
    return {{-100, 0, 120}, {150, 0, 120}, {185, 0, 175}, {300, 0, 175}, {420, 0, 120}};
  if (name == "bench2")
    return {{-100, 0, 120}, {150, 0, 120}, {200, 45, 120}, {250, 0, 120}, {420, 0, 120}};
  if (name == "bench3")
    return {{-100, 0, 120}, {150, 0, 120}, {180, 0, 175}, {300, 0, 175}, {420, 0, 120}};
  if (name == "bench4")
    return {{-100, 0, 120}, {140, 0, 120}, {200, 60, 120}, {260, 0, 120}, {420, 0, 120}};
  if (name == "bench5")
    return {{-100, 0, 120},  {80, 35, 120},   {160, 35, 120},
            {280, -35, 120}, {360, -35, 120}, {450, 0, 120}};
  if (name == "bench6")
    return {{-100, 0, 120}, {170, 0, 120}, {240, 40, 120}, {320, 40, 120}, {450, 0, 120}};
  if (name == "tree")
    return {{-100, 0, 60}, {220, 0, 60}, {260, 0, 115}, {340, 0, 115}, {420, 0, 60}};
  return {};
}

struct MappedFlight {
  std::vector<mapping::ObstacleEntry> obstacles;
  std::vector<Vec3> true_hits;  // noise-free obstacle hits of every beam the sensor got back
  mapping::MapperConfig config;
  int64_t scans = 0;
  int64_t points = 0;
};

struct SensorFaults {
  double outlier_probability = 0;
  double dropout_probability = 0.01;
  double saturation_probability = 0;
  bool ignore_status = false;  // a broken interface that trusts every range
};

/// Called after each scan has been mapped, with the time at its end.
using ScanHook = std::function<void(mapping::Mapper&, double t)>;

/// The obstacles present at time t, as the obstacle injector sends them.
std::vector<ObstacleSpec> present_at(const std::vector<ObstacleSpec>& all, double t) {
  std::vector<ObstacleSpec> present;
  for (const auto& o : all)
    if (o.present_at(t)) present.push_back(o);
  return present;
}

MappedFlight fly_and_map(const Scenario& scenario, const std::vector<Vec3>& path_ft,
                         const SensorFaults& faults = {}, const ScanHook& hook = {},
                         mapping::MapperConfig config = {}) {
  world::World world(scenario.obstacles, scenario.ground_altitude);
  const KinematicPath path(path_ft);

  vehicle::LidarConfig lidar_config;
  lidar_config.outlier_probability = faults.outlier_probability;
  lidar_config.dropout_probability = faults.dropout_probability;
  lidar_config.saturation_probability = faults.saturation_probability;
  vehicle::LidarHead lidar(lidar_config, scenario.limits.sensor_range);

  sensing::PoseBuffer poses;
  sensing::ScanProcessor processor;
  config.occupancy.max_range = lidar.max_range();
  mapping::Mapper mapper(config);

  MappedFlight result;
  result.config = config;
  const Utime period = lidar.period_us();
  const Utime nav_step = to_utime(0.01);
  Utime nav_time = 0;
  Utime next_cycle = to_utime(1.0);
  for (Utime t0 = 0; to_seconds(t0) < path.duration(); t0 += period) {
    world.set_obstacles(present_at(scenario.obstacles, to_seconds(t0)));
    const vehicle::LidarScan scan = lidar.scan(
        t0, [&](Utime t) { return path.pose(t); }, world);
    // Navigation at 100 Hz up to the end of the scan, as NAV_STATE would.
    for (; nav_time <= t0 + period; nav_time += nav_step) {
      const auto [p, q] = path.pose(nav_time);
      sensing::Pose pose;
      pose.utime = nav_time;
      pose.position = p;
      pose.attitude = q;
      pose.velocity = (path.pose(nav_time + 1000).first - p) / 1e-3;
      poses.insert(pose);
    }
    sensing::RawScan raw;
    raw.utime = scan.utime;
    raw.scan_index = scan.scan_index;
    raw.max_range = scan.max_range;
    for (const auto& b : scan.beams) {
      sensing::RawBeam rb;
      rb.dt_us = b.dt_us;
      rb.elevation = b.elevation;
      rb.layer_angle = b.layer_angle;
      rb.range = b.range;
      rb.status = faults.ignore_status && b.status == vehicle::kLidarSaturated
                      ? sensing::BeamStatus::kOk
                      : static_cast<sensing::BeamStatus>(b.status);
      raw.beams.push_back(rb);
      if (b.truth_id > 0 && b.status == vehicle::kLidarOk) {
        // Where the beam really ended, without noise: the part of the
        // obstacle the sensor has seen.
        const auto [p, q] = path.pose(scan.utime + b.dt_us);
        const Vec3 dir = q * (lidar.config().mount().body_from_sensor *
                              beam_direction_sensor(b.elevation, b.layer_angle));
        const Vec3 origin = lidar.config().mount().origin_world(p, q);
        if (auto hit = world.ray_cast(origin, dir, lidar.max_range()); hit && hit->obstacle_id > 0)
          result.true_hits.push_back(origin + dir * hit->range);
      }
    }
    const auto processed = processor.process(raw, poses);
    if (processed.status != sensing::ScanStatus::kOk) continue;
    mapping::ScanInput input;
    input.utime = processed.scan.utime;
    input.sensor_origin = processed.scan.sensor_origin;
    input.points = processed.scan.points;
    input.free_ray_ends = processed.scan.free_ray_ends;
    mapper.set_vehicle_position(path.pose(t0 + period).first);
    mapper.add_scan(input);
    if (t0 + period >= next_cycle) {
      mapper.update_cuboids(t0 + period);
      next_cycle += to_utime(1.0);
    }
    if (hook) hook(mapper, to_seconds(t0 + period));
  }
  mapper.update_cuboids(next_cycle);
  result.obstacles = mapper.obstacles();
  result.scans = mapper.counters().scans;
  result.points = mapper.counters().points;
  return result;
}

/// Smallest distance from a cuboid's volume to an obstacle's surface,
/// sampled on a lattice inside the cuboid (0 when they overlap).
double cuboid_to_obstacle(const mapping::Cuboid& c, const world::Obstacle& o) {
  double best = INFINITY;
  const double top = std::min(c.top_altitude(), o.spec().height);
  for (double n = c.min.x(); n <= c.max.x() + 1e-9; n += 0.5)
    for (double e = c.min.y(); e <= c.max.y() + 1e-9; e += 0.5)
      for (double h = 0.5; h <= top; h += 1.0)
        best = std::min(best, o.distance(Vec3(std::min(n, c.max.x()), std::min(e, c.max.y()), -h)));
  return best;
}

/// The true top of an obstacle over a cuboid's footprint (highest surface
/// point found by vertical rays).
double true_top_over(const mapping::Cuboid& c, const world::Obstacle& o) {
  double top = 0;
  for (double n = c.min.x(); n <= c.max.x(); n += 0.25)
    for (double e = c.min.y(); e <= c.max.y(); e += 0.25)
      if (auto d = o.ray_cast(Vec3(n, e, -500), Vec3::UnitZ(), 1000)) top = std::max(top, 500 - *d);
  return top;
}

bool inside(const mapping::Cuboid& c, const Vec3& p, double tol) {
  return p.x() >= c.min.x() - tol && p.x() <= c.max.x() + tol && p.y() >= c.min.y() - tol &&
         p.y() <= c.max.y() + tol && p.z() >= c.min.z() - tol && p.z() <= c.max.z() + tol;
}

/// Every cuboid stands on or next to a real obstacle (none where none is).
void expect_no_phantoms(const MappedFlight& r, const world::World& world, double tol) {
  for (const auto& e : r.obstacles) {
    double nearest = INFINITY;
    for (const auto& o : world.obstacles())
      nearest = std::min(nearest, cuboid_to_obstacle(e.cuboid, o));
    EXPECT_LE(nearest, tol) << "cuboid " << e.id << " [" << e.cuboid.min.transpose() << "] - ["
                            << e.cuboid.max.transpose() << "] stands where no obstacle is";
  }
}

class CourseMapping : public ::testing::TestWithParam<std::string> {};

TEST_P(CourseMapping, CuboidsCoverTheObstaclesWithTheRightTopsAndNothingElse) {
  const std::string name = GetParam();
  const Scenario scenario = load_scenario(scenario_path(name));
  ASSERT_FALSE(scenario.obstacles.empty());
  const world::World world(scenario.obstacles, scenario.ground_altitude);
  const MappedFlight r = fly_and_map(scenario, course_path(name));
  ASSERT_GT(r.scans, 100);
  ASSERT_FALSE(r.true_hits.empty());
  ASSERT_FALSE(r.obstacles.empty());
  const double cell = r.config.grid.resolution;
  const double margin = r.config.grid.safety_margin;

  // Covered: what the sensor saw of each obstacle lies inside a cuboid.
  size_t covered = 0;
  std::ostringstream missed;
  for (const auto& p : r.true_hits) {
    bool in_one = false;
    for (const auto& e : r.obstacles) in_one = in_one || inside(e.cuboid, p, cell);
    if (in_one)
      ++covered;
    else if (missed.tellp() < 300)
      missed << " (" << p.transpose() << ")";
  }
  EXPECT_GE(static_cast<double>(covered), 0.99 * r.true_hits.size())
      << covered << " of " << r.true_hits.size() << " true hits inside a cuboid; missed e.g."
      << missed.str();

  expect_no_phantoms(r, world, margin + 2 * cell);

  // Tops: within one cell plus the margin of the truth where the sensor saw
  // over the obstacle; never below the truth where it did not.
  for (const auto& e : r.obstacles) {
    double truth = 0;
    for (const auto& o : world.obstacles())
      if (cuboid_to_obstacle(e.cuboid, o) <= margin + 2 * cell)
        truth = std::max(truth, true_top_over(e.cuboid, o));
    if (e.cuboid.top_observed)
      EXPECT_NEAR(e.cuboid.top_altitude(), truth, cell + margin) << "cuboid " << e.id;
    else
      EXPECT_GE(e.cuboid.top_altitude(), truth) << "cuboid " << e.id;
  }
}

INSTANTIATE_TEST_SUITE_P(Benchmarks, CourseMapping,
                         ::testing::Values("bench1", "bench2", "bench3", "bench4", "bench5",
                                           "bench6", "tree"));

TEST(MappingRobustness, OutliersAndDropoutsRaiseNoPhantomCuboid) {
  for (const std::string name : {"bench2", "bench6"}) {
    const Scenario scenario = load_scenario(scenario_path(name));
    const world::World world(scenario.obstacles, scenario.ground_altitude);
    SensorFaults faults;
    faults.outlier_probability = 0.01;
    faults.dropout_probability = 0.05;
    const MappedFlight r = fly_and_map(scenario, course_path(name), faults);
    ASSERT_FALSE(r.obstacles.empty()) << name;
    expect_no_phantoms(r, world, r.config.grid.safety_margin + 2 * r.config.grid.resolution);
  }
}

// The paper's first bench3 flight: a saturated sensor held its last range,
// the wall read far taller than it is and the vehicle went around it.
TEST(MappingRobustness, SaturatedReturnsNeverRaiseAnObstacle) {
  const Scenario scenario = load_scenario(scenario_path("bench3"));
  const double wall_top = scenario.obstacles.at(0).height;
  const double tol = 1.0 + 1.5;  // one grid cell plus the safety margin
  for (const double probability : {0.5, 1.0}) {
    SensorFaults faults;
    faults.saturation_probability = probability;
    const MappedFlight r = fly_and_map(scenario, course_path("bench3"), faults);
    ASSERT_FALSE(r.obstacles.empty());
    // Every top the mapper claims to have seen is the wall's. With half the
    // beams that pass over the wall saturated, the rest still show its top;
    // with all of them saturated nothing shows it, and the top stays unknown.
    int seen_at_wall_top = 0;
    for (const auto& e : r.obstacles) {
      if (!e.cuboid.top_observed) continue;
      EXPECT_LE(e.cuboid.top_altitude(), wall_top + tol) << "cuboid " << e.id;
      if (std::abs(e.cuboid.top_altitude() - wall_top) <= tol) ++seen_at_wall_top;
    }
    if (probability < 1.0) {
      EXPECT_GT(seen_at_wall_top, 0);
    }
  }

  // Half-saturated scans through an interface that trusts saturated ranges
  // reproduce the failure: the held ranges stack above the wall and no part
  // of it keeps its true top, so a planner would go around.
  SensorFaults faults;
  faults.saturation_probability = 0.5;
  faults.ignore_status = true;
  const MappedFlight broken = fly_and_map(scenario, course_path("bench3"), faults);
  ASSERT_FALSE(broken.obstacles.empty());
  for (const auto& e : broken.obstacles)
    EXPECT_GT(e.cuboid.top_altitude(), wall_top + tol) << "cuboid " << e.id;
}

/// Highest filtered-grid cell within a footprint (m above ground).
double grid_top_within(mapping::Mapper& mapper, double n0, double n1, double e0, double e1) {
  const mapping::Heightfield& g = mapper.grid();
  double top = 0;
  for (int r = 0; r < g.rows; ++r)
    for (int c = 0; c < g.cols; ++c) {
      const double n = g.cell_centre_north(r), e = g.cell_centre_east(c);
      if (n >= n0 && n <= n1 && e >= e0 && e <= e1) top = std::max(top, double(g.at(r, c)));
    }
  return top;
}

bool database_has_obstacle_over(const mapping::Mapper& mapper, double n0, double n1, double e0,
                                double e1) {
  for (const auto& e : mapper.obstacles())
    if (e.cuboid.max.x() > n0 && e.cuboid.min.x() < n1 && e.cuboid.max.y() > e0 &&
        e.cuboid.min.y() < e1)
      return true;
  return false;
}

Scenario straight_course_with(const ObstacleSpec& obstacle) {
  Scenario s = load_scenario(scenario_path("open"));
  s.obstacles = {obstacle};
  return s;
}

TEST(MappingDynamics, PopUpObstacleIsInTheGridWithinOneScanPeriod) {
  ObstacleSpec box;
  box.id = 1;
  box.north = 150 * kFt;  // 60 m ahead of the vehicle at t = 12 s, in range and in view
  box.length = box.width = 40 * kFt;
  box.height = 160 * kFt;
  box.appear_time = 12.0;
  const Scenario scenario = straight_course_with(box);
  const double period = 1.0 / vehicle::LidarConfig{}.scan_rate;
  double seen_at = -1;
  fly_and_map(scenario, {{-100, 0, 120}, {150, 0, 120}}, {}, [&](mapping::Mapper& m, double t) {
    if (seen_at >= 0 || t > 20) return;
    const double top = grid_top_within(m, box.north - 20 * kFt, box.north + 20 * kFt, -6, 6);
    if (t < box.appear_time) {
      EXPECT_EQ(top, 0.0) << "obstacle mapped before it appeared, t = " << t;
    } else if (top > 5.0) {
      seen_at = t;
    }
  });
  ASSERT_GE(seen_at, 0) << "pop-up never mapped";
  // The first scan that starts after the pop-up ends one period later.
  EXPECT_LE(seen_at - box.appear_time, 2 * period + 1e-6);
}

TEST(MappingDynamics, RemovedObstacleIsRetired) {
  ObstacleSpec box;
  box.id = 1;
  box.north = 130 * kFt;
  box.length = box.width = 30 * kFt;
  box.height = 100 * kFt;
  box.disappear_time = 7.0;  // the vehicle is 160 ft short of it, looking at it
  const Scenario scenario = straight_course_with(box);
  const double n0 = box.north - 15 * kFt, n1 = box.north + 15 * kFt, e0 = -15 * kFt, e1 = 15 * kFt;
  bool held_before = false, retired_after = false;
  fly_and_map(scenario, {{-100, 0, 120}, {120, 0, 120}}, {}, [&](mapping::Mapper& m, double t) {
    if (t > 6.0 && t < 6.9)
      held_before = held_before || database_has_obstacle_over(m, n0, n1, e0, e1);
    if (t > 18.0 && t < 19.0) retired_after = !database_has_obstacle_over(m, n0, n1, e0, e1);
  });
  EXPECT_TRUE(held_before) << "the obstacle never entered the database";
  EXPECT_TRUE(retired_after) << "the removed obstacle is still in the database 11 s later";
}

// A top is in OBSTACLE_GRID at its height only where a beam went over it.
// bench1's wall (140 ft) is looked over from the approach: the grid holds it
// at its top all along it, also where the sweep hit it once from far away.
// The cul-de-sac's back wall (600 ft) is seen from below only, up to where
// the scan stops looking (42.5 deg): the grid holds it at the ceiling, not
// at the height of the highest hit, which a climbing vehicle would reach.
TEST(MappingTops, ATopNoBeamWentOverStandsAtTheCeiling) {
  const double tol = 1.0 + 1.5;  // one grid cell plus the safety margin
  {
    const Scenario scenario = load_scenario(scenario_path("bench1"));
    const ObstacleSpec& wall = scenario.obstacles.at(0);
    double top = 0;
    fly_and_map(scenario, {{-100, 0, 120}, {120, 0, 120}}, {}, [&](mapping::Mapper& m, double t) {
      if (t > 14.0)
        top = std::max(top, grid_top_within(m, wall.north - 10 * kFt, wall.north + 10 * kFt,
                                            -200 * kFt, 200 * kFt));
    });
    EXPECT_GT(top, wall.height - tol);
    EXPECT_LT(top, wall.height + tol);
  }
  {
    const Scenario scenario = load_scenario(scenario_path("trap_cul_de_sac"));
    const ObstacleSpec& back = scenario.obstacles.at(2);
    mapping::MapperConfig config;
    double top = 0;
    fly_and_map(scenario, {{-100, 0, 120}, {240, 0, 120}}, {}, [&](mapping::Mapper& m, double t) {
      if (t > 30.0)
        top = grid_top_within(m, back.north - 10 * kFt, back.north + 10 * kFt, -20 * kFt, 20 * kFt);
    });
    EXPECT_GE(top, config.grid.ceiling - 1e-3);
  }
}

// A long box beside the path, its end towards the vehicle, 1 m above the
// flight altitude, flown past as in dense field 7 (turning towards it at
// the end): the sweep looks at its end and the corner next to the path,
// seldom at its side. With top_over_hits, wherever the scanner hit the box
// the grid shows it at its top or higher (unseen: the ceiling), never at
// the height where grazing beams stopped hitting the corner, which a
// vehicle at flight altitude would fly over. Without it, it does (the
// second flight): the rule is what holds the tops.
TEST(MappingTops, AGrazedCornerIsNotMappedBelowItsTop) {
  ObstacleSpec box;
  box.id = 1;
  box.north = 106.5;
  box.east = 17.7;
  box.length = 20.8;
  box.width = 6.4;
  box.yaw = 1.83;
  box.height = 37.5;  // flight altitude 120 ft = 36.6 m
  const Scenario scenario = straight_course_with(box);
  const std::vector<Vec3> path_ft = {{-100, 0, 120}, {298, 1, 120},  {322, -2, 120},
                                     {342, 1, 120},  {359, 10, 120}, {376, 21, 120},
                                     {385, 26, 120}, {430, 45, 120}};
  const double tol = 1.0 + 1.5;  // one grid cell plus the safety margin
  const Eigen::Rotation2Dd to_box(-box.yaw);
  struct Count {
    int checked = 0, low = 0;
    std::string first_low;
  };
  const auto fly = [&](bool top_over_hits) {
    mapping::MapperConfig config;
    config.top_over_hits = top_over_hits;
    Count n;
    const auto check = [&](mapping::Mapper& m, double t) {
      const mapping::Heightfield& g = m.grid();
      const mapping::Heightfield& raw = m.raw_grid();
      for (int r = 0; r < g.rows; ++r)
        for (int c = 0; c < g.cols; ++c) {
          // Cells the scanner hit: the rest of the box shows only as the
          // ramp beside its faces (the optimiser's shadows stand in for it).
          if (!(raw.at(r, c) > 0.0f)) continue;
          // Inside the box by half a cell.
          const Eigen::Vector2d local = to_box * Eigen::Vector2d(g.cell_centre_north(r) - box.north,
                                                                 g.cell_centre_east(c) - box.east);
          if (std::abs(local.x()) > 0.5 * box.length - 0.5 ||
              std::abs(local.y()) > 0.5 * box.width - 0.5)
            continue;
          ++n.checked;
          if (g.at(r, c) >= box.height - tol) continue;
          if (n.low++ == 0) {
            std::ostringstream where;
            where << g.at(r, c) << " m at t = " << t << " s, (" << g.cell_centre_north(r) << ", "
                  << g.cell_centre_east(c) << ")";
            n.first_low = where.str();
          }
        }
    };
    fly_and_map(scenario, path_ft, {}, check, config);
    return n;
  };
  const Count with_rule = fly(true);
  EXPECT_GT(with_rule.checked, 10);
  EXPECT_EQ(with_rule.low, 0) << "first: " << with_rule.first_low;
  const Count without_rule = fly(false);
  EXPECT_GT(without_rule.low, 0);
}

}  // namespace
}  // namespace ofn
