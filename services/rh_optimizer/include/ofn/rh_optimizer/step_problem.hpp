#pragma once
// What one RH step solves (Eqs. 1-8's problem), framed from the active leg
// or from a dead-end recovery's escape leg. The guidance frame runs along
// the leg; x_f (Eq. 6) is where the mapped space ahead ends (terminal_x);
// with the leg's end inside that horizon the plan stops there. An escape
// leg runs from where the escape began to a point with room to stop near
// the route's corner, and relaxes Eq. 8's forward-speed rule (the route
// may bend back); nothing else about the problem is relaxed.
// Pure core: world NED, SI.

#include "ofn/map/heightfield.hpp"
#include "ofn/rh_optimizer/avoidance_switch.hpp"
#include "ofn/rh_optimizer/rh_optimizer.hpp"
#include "ofn/rh_optimizer/rh_planner.hpp"
#include "ofn/rh_optimizer/start_state.hpp"

namespace ofn::rh {

struct FramingSettings {
  double clearance_margin = 0.3;  // m planned beyond R_s (optimizer.clearance_margin)
  /// m, the least clearance the solver accepts as met: R_s plus the margin
  /// less its feasibility tolerance. An escape ends where this is found
  /// when nothing roomier is.
  double pinch_clearance = 0.0;
  double max_shift = 3.0;  // m an escape's end may move from the route's corner
};

/// The escape's end is kept this much (m) beyond the planned clearance
/// where that fits.
inline constexpr double kEscapeEndMargin = 0.3;

/// The step's problem along `leg` from `start`, the map's horizon judged
/// from the measured `vehicle` position; `final_leg`: the leg ends at the
/// last waypoint, so the plan stops there once it is within the horizon.
RhProblem leg_problem(const Leg& leg, bool final_leg, const StartState& start, const Vec3& vehicle,
                      const Limits& limits, const ClearanceQuery& clearance,
                      const mapping::Heightfield& grid, const FramingSettings& settings);

/// `problem` reframed along an escape from `escape_from` towards the route
/// corner `escape_point`: the leg ends at the first point room_to_stop
/// finds within max_shift of the corner with the planned clearance plus
/// kEscapeEndMargin, else with the planned clearance, else with the pinch
/// clearance, else at the corner itself. Returns the leg's end.
Vec3 frame_escape(RhProblem* problem, const Vec3& escape_from, const Vec3& escape_point,
                  const Vec3& vehicle, const mapping::Heightfield& grid,
                  const FramingSettings& settings);

/// The step's plan moves the vehicle off: solved (not a fallback), not a
/// stall, and its end more than `distance` (m) from its start. A dead-end
/// recovery counts the vehicle stuck while no plan does.
bool plan_moves_off(const StepOutput& out, double distance);

}  // namespace ofn::rh
