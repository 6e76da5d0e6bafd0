#include "ofn/rh_optimizer/step_problem.hpp"

#include <algorithm>

#include "ofn/rh_optimizer/narrow_passage.hpp"

namespace ofn::rh {
namespace {

// The map's horizon is never judged shorter than this (m): four
// clearances, or the sensor range where that is less.
double min_horizon(const Limits& limits) {
  return std::min(limits.sensor_range, 4.0 * limits.clearance);
}

}  // namespace

RhProblem leg_problem(const Leg& leg, bool final_leg, const StartState& start, const Vec3& vehicle,
                      const Limits& limits, const ClearanceQuery& clearance,
                      const mapping::Heightfield& grid, const FramingSettings& settings) {
  RhProblem p;
  p.frame = GuidanceFrame::from_leg(leg.from, leg.to);
  p.position = start.position;
  p.velocity = start.velocity;
  p.acceleration = start.acceleration;
  p.target = leg.to;
  const double x_target = p.frame.to_guidance(leg.to).x();
  p.terminal_x =
      terminal_x(p.frame, grid, vehicle, limits.sensor_range,
                 limits.clearance + settings.clearance_margin, x_target, min_horizon(limits));
  // With the last waypoint within the horizon, plan the stop there: a
  // trajectory that only has to reach its x would arrive at cruise speed and
  // leave waypoint guidance no room to brake.
  p.stop_at_target = final_leg && p.terminal_x >= x_target;
  p.limits = limits;
  p.clearance = clearance;
  return p;
}

Vec3 frame_escape(RhProblem* problem, const Vec3& escape_from, const Vec3& escape_point,
                  const Vec3& vehicle, const mapping::Heightfield& grid,
                  const FramingSettings& settings) {
  RhProblem& p = *problem;
  const Limits limits = p.limits;
  const double planned_clearance = limits.clearance + settings.clearance_margin;
  // The end is looked for as the route check looked for room at the corner
  // (room_to_stop): kept kEscapeEndMargin beyond the clearance where that
  // fits, else at the clearance, else at what the check asked (the
  // clearance less the solver's tolerance), which the check found. Searched
  // another way (a gradient, then rings), a corner the check passed could
  // be one where the escape found no end, and stalled.
  Vec3 leg_end = escape_point;
  for (const double wanted :
       {planned_clearance + kEscapeEndMargin, planned_clearance, settings.pinch_clearance})
    if (const auto room = room_to_stop(p.clearance, escape_point, wanted, settings.max_shift)) {
      leg_end = *room;
      break;
    }
  p.frame = GuidanceFrame::from_leg(escape_from, leg_end);
  p.target = leg_end;
  const double x_escape = p.frame.to_guidance(leg_end).x();
  p.terminal_x = terminal_x(p.frame, grid, vehicle, limits.sensor_range, planned_clearance,
                            x_escape, min_horizon(limits));
  p.stop_at_target = p.terminal_x >= x_escape;
  p.limits.min_forward_speed = -limits.max_speed;
  return leg_end;
}

bool plan_moves_off(const StepOutput& out, double distance) {
  return out.mode == StepMode::kSolved && !out.stalled &&
         (out.trajectory.position(out.trajectory.duration()) - out.trajectory.position(0.0))
                 .norm() > distance;
}

}  // namespace ofn::rh
