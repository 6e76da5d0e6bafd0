// The offline time-optimal baseline on the benchmark courses: the open
// course at full speed, the wall climbed over with R_s kept, the baffle's
// detour slower than the open course and never below the lower bounds,
// every returned sample within the limits, bad scenarios rejected.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <random>
#include <stdexcept>
#include <string>

#include "ofn/common/frames.hpp"
#include "ofn/common/scenario.hpp"
#include "ofn/sim/time_optimal.hpp"
#include "ofn/world/world.hpp"

namespace ofn::baseline {
namespace {

constexpr double kFt = kMetresPerFoot;
// The final check's tolerance (BaselineSettings::tolerance) and a hair for
// the output sampling.
constexpr double kTolerance = 0.005 + 1e-6;

Scenario load_course(const std::string& name) {
  const auto path = std::filesystem::path(OFN_SOURCE_DIR) / "sim" / "scenarios" / (name + ".yaml");
  return load_scenario(path.string());
}

// Each course is solved once for all the tests that look at it.
const BaselineResult& solved(const std::string& name) {
  static std::map<std::string, BaselineResult> cache;
  auto it = cache.find(name);
  if (it == cache.end()) it = cache.emplace(name, compute_time_optimal(load_course(name))).first;
  return it->second;
}

void expect_within_limits(const Scenario& s, const BaselineResult& r) {
  const world::World world(s.obstacles, s.ground_altitude);
  const Limits& l = s.limits;
  ASSERT_FALSE(r.trajectory.empty());
  for (const auto& p : r.trajectory) {
    SCOPED_TRACE("t = " + std::to_string(p.t));
    EXPECT_LE(p.velocity.norm(), l.max_speed * (1 + kTolerance));
    EXPECT_LE(p.acceleration.norm(), l.max_accel * (1 + kTolerance));
    EXPECT_LE(std::abs(p.velocity.z()), l.max_vertical_speed * (1 + kTolerance));
    EXPECT_GE(p.velocity.x(), l.min_forward_speed - kTolerance * l.max_speed);
    EXPECT_GE(world.distance_to_obstacles(p.position), l.clearance * (1 - kTolerance));
    EXPECT_GE(-p.position.z() - s.ground_altitude,
              std::min(l.clearance, -s.start_position.z()) - kTolerance * l.clearance);
  }
  // From the start state to the finish gate.
  EXPECT_NEAR((r.trajectory.front().position - s.start_position).norm(), 0.0, 1e-6);
  EXPECT_NEAR((r.trajectory.front().velocity - s.start_velocity).norm(), 0.0, 1e-6);
  EXPECT_NEAR(r.trajectory.back().position.x(), *s.finish_gate, 1e-3);
}

TEST(TimeOptimal, OpenCourseFliesTheGatesAtFullSpeed) {
  const Scenario s = load_course("open");
  const BaselineResult& r = solved("open");
  ASSERT_TRUE(r.feasible) << r.reason;
  const double straight = (*s.finish_gate - *s.start_gate) / s.limits.max_speed;
  EXPECT_NEAR(straight, 40.0, 1e-9);
  EXPECT_NEAR(r.gate_to_gate, straight, 0.01 * straight);
  EXPECT_GE(r.gate_to_gate, r.lower_bound * (1 - kTolerance));
  EXPECT_EQ(r.route, "straight");
  EXPECT_LE(r.worst_violation, 0.005);
}

TEST(TimeOptimal, WallIsClimbedOverKeepingTheClearance) {
  const Scenario s = load_course("bench1");
  const BaselineResult& r = solved("bench1");
  ASSERT_TRUE(r.feasible) << r.reason;
  EXPECT_EQ(r.route, "over");
  // A 40 ft climb beside a 400 ft leg costs little: close to the open course.
  EXPECT_GE(r.gate_to_gate, r.lower_bound * (1 - kTolerance));
  EXPECT_LT(r.gate_to_gate, 41.0);
  // Over the wall (140 ft high, 10 ft thick at x = 200 ft) at R_s above it.
  const world::World world(s.obstacles, s.ground_altitude);
  double highest_over_wall = 0;
  for (const auto& p : r.trajectory) {
    EXPECT_GE(world.distance_to_obstacles(p.position), s.limits.clearance * (1 - kTolerance));
    if (std::abs(p.position.x() - 200 * kFt) < 5 * kFt)
      highest_over_wall = std::max(highest_over_wall, -p.position.z());
  }
  EXPECT_GE(highest_over_wall, (140 + 20) * kFt * (1 - kTolerance));
  EXPECT_GE(r.min_clearance, s.limits.clearance * (1 - kTolerance));
}

TEST(TimeOptimal, BaffleDetourIsSlowerThanTheOpenCourseAndAboveTheBounds) {
  const BaselineResult& open = solved("open");
  const BaselineResult& r = solved("bench5");
  ASSERT_TRUE(r.feasible) << r.reason;
  EXPECT_GT(r.gate_to_gate, open.gate_to_gate + 0.5);
  EXPECT_GE(r.gate_to_gate, r.lower_bound * (1 - kTolerance));
  EXPECT_GE(r.finish_gate_time, r.total_time_lower_bound * (1 - kTolerance));
  // From the start the baffle forces a zigzag: the bound sees it.
  EXPECT_GT(r.total_path_length_lower_bound, 500 * kFt + 0.5);
  // Round the open end of each wall: y > 10 ft at the first, y < -10 ft at the second.
  EXPECT_EQ(r.route, "right-left");
}

TEST(TimeOptimal, TowerIsPassedBesideNotOver) {
  const BaselineResult& r = solved("bench2");
  ASSERT_TRUE(r.feasible) << r.reason;
  EXPECT_TRUE(r.route == "left" || r.route == "right") << r.route;
  EXPECT_GT(r.gate_to_gate, solved("open").gate_to_gate);
  EXPECT_GE(r.gate_to_gate, r.lower_bound * (1 - kTolerance));
}

TEST(TimeOptimal, EveryReturnedSampleKeepsTheLimits) {
  for (const std::string name : {"open", "bench1", "bench5", "bench2"}) {
    SCOPED_TRACE(name);
    const BaselineResult& r = solved(name);
    ASSERT_TRUE(r.feasible) << r.reason;
    EXPECT_LE(r.worst_violation, 0.005);
    expect_within_limits(load_course(name), r);
  }
}

TEST(TimeOptimal, RandomFieldOfBoxesAndCylindersIsSolved) {
  Scenario s = load_course("open");
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> north(60, 340), east(-60, 60), size(15, 50),
      height(80, 250);
  for (int i = 0; i < 4; ++i) {
    ObstacleSpec o;
    o.id = i + 1;
    o.kind = i % 2 ? ObstacleSpec::Kind::kCylinder : ObstacleSpec::Kind::kBox;
    o.north = north(rng) * kFt;
    o.east = east(rng) * kFt;
    o.length = size(rng) * kFt;
    o.width = o.kind == ObstacleSpec::Kind::kBox ? size(rng) * kFt : o.length;
    o.height = height(rng) * kFt;
    s.obstacles.push_back(o);
  }
  const BaselineResult r = compute_time_optimal(s);
  ASSERT_TRUE(r.feasible) << r.reason;
  EXPECT_GE(r.gate_to_gate, r.lower_bound * (1 - kTolerance));
  EXPECT_GE(r.finish_gate_time, r.total_time_lower_bound * (1 - kTolerance));
  expect_within_limits(s, r);
}

TEST(TimeOptimal, ScenarioWithoutGatesIsRejectedWithAClearError) {
  Scenario s = load_course("open");
  s.start_gate.reset();
  s.finish_gate.reset();
  try {
    compute_time_optimal(s);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("gates"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("open"), std::string::npos) << e.what();
  }
  Scenario behind = load_course("open");
  behind.start_position.x() = *behind.start_gate + 1.0;
  EXPECT_THROW(compute_time_optimal(behind), std::invalid_argument);
  EXPECT_THROW(path_length_lower_bound(s), std::invalid_argument);
}

}  // namespace
}  // namespace ofn::baseline
