#pragma once
// Receding-horizon steps for the planner's tests: level flight north at the
// benchmarks' speed limit along a leg from the origin to 300 m north, over
// a field of boxes.

#include <memory>
#include <utility>
#include <vector>

#include "ofn/map/distance_field.hpp"
#include "ofn/rh_optimizer/rh_planner.hpp"

namespace ofn::rh::testing_support {

/// The optimiser's settings with no wall-time limit per solve: that limit
/// (max_solve_time, 50 ms) is for flight, and in a test it would make the
/// outcome depend on the machine's load (a cold solve of the tree course
/// ran out of it beside two Monte Carlo flights).
inline RhSettings untimed(RhSettings settings = {}) {
  settings.max_solve_time = 60.0;
  return settings;
}

inline const Limits kBenchmarkLimits{3.048, 0.4877, 1.524, 0.0, 6.096, 60.96};  // SI
constexpr double kLegAltitude = 30.0;                                           // m

/// A box on the ground: north [north_lo, north_hi), east [east_lo, east_hi), m.
struct Box {
  int north_lo, north_hi, east_lo, east_hi;
  float top;  // m above ground
};

/// The map of north [-20, 180), east [-60, 60) with these boxes, 1 m cells.
inline mapping::Heightfield heightfield_with(const std::vector<Box>& boxes) {
  mapping::Heightfield heightfield;
  heightfield.origin_north = -20;
  heightfield.origin_east = -60;
  heightfield.rows = 200;
  heightfield.cols = 120;
  heightfield.top.assign(static_cast<size_t>(heightfield.rows) * heightfield.cols, 0.0f);
  for (const Box& b : boxes)
    for (int n = b.north_lo; n < b.north_hi; ++n)
      for (int e = b.east_lo; e < b.east_hi; ++e) {
        const int r = heightfield.row_of(n + 0.5), c = heightfield.col_of(e + 0.5);
        if (heightfield.inside(r, c)) heightfield.at(r, c) = b.top;
      }
  return heightfield;
}

/// The clearance over north [-20, 180), east [-60, 60) with these boxes.
inline ClearanceQuery field_with(const std::vector<Box>& boxes) {
  auto field = std::make_shared<mapping::DistanceField>();
  field->build(heightfield_with(boxes), 0.0, 80.0);
  return [field](const Vec3& ned) { return field->query(ned); };
}

/// A step at `time` from `position` at the speed limit along the leg.
inline StepInput step_input_at(const Vec3& position, double time, ClearanceQuery clearance) {
  StepInput input;
  input.time = time;
  RhProblem& p = input.problem;
  p.frame = GuidanceFrame::from_leg(Vec3(0, 0, -kLegAltitude), Vec3(300, 0, -kLegAltitude));
  p.position = position;
  p.velocity = Vec3(kBenchmarkLimits.max_speed, 0, 0);
  p.target = Vec3(300, 0, -kLegAltitude);
  p.terminal_x = position.x() + kBenchmarkLimits.sensor_range;
  p.limits = kBenchmarkLimits;
  p.clearance = std::move(clearance);
  return input;
}

}  // namespace ofn::rh::testing_support
