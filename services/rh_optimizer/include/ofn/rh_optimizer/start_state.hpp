#pragma once
// Where each RH step's plan starts (Eq. 5's initial state). On the last
// plan, where the vehicle is near it: starting every plan at the measured
// state would reset the controller's reference to the vehicle ten times a
// second, so its feedback would never act and each lag behind a manoeuvre
// would be accepted into the next plan (the vehicle slowed to half speed
// topping bench1's wall while every plan said full speed). At the measured
// state where the vehicle is off the plan by more than the replan errors,
// or there is no plan covering now. The acceleration a(t0) is fixed by
// construction (Eq. 5), so what it is set to is what the plan starts with:
// the planned one (zero with no plan, as waypoint guidance commands in
// cruise when avoidance has just engaged), or, if asked, the measured one,
// which carries the scanner's yaw-sweep oscillation and gust noise, capped
// at the acceleration limit.
//
// A stop (a braking, a hover to look round, a hover with no route) is held
// further: its rest point was checked clear when it was committed, so a
// vehicle a gust has pushed off it is flown back to it by the controller,
// with the controller's authority, while it is within stop_recapture_error.
// Re-planning the stop from the pushed state would take the gust's velocity
// into the reference and brake it at the envelope's acceleration, metres on
// towards whatever the gust pushed the vehicle at (15 kt fields, RESULTS.md).
// Past its end a stop stays a hover at its rest point.
// Pure core: world NED, SI, seconds.

#include "ofn/common/bspline.hpp"
#include "ofn/common/frames.hpp"

namespace ofn::rh {

struct StartStateSettings {
  bool planned_initial_state = true;         // position and velocity from the last plan
  double replan_position_error = 3.0;        // m; farther from the plan, start from the vehicle
  double replan_velocity_error = 1.5;        // m/s
  bool planned_initial_acceleration = true;  // a(t0) from the last plan, not the measured one
  double stop_recapture_error = 6.0;         // m; nearer a stop than this, hold it (0: as a plan)
};

/// What the last plan was: a stop ends at rest at a point checked clear.
enum class LastPlan { kMoving, kStop };

struct MeasuredState {
  Vec3 position = Vec3::Zero();
  Vec3 velocity = Vec3::Zero();
  Vec3 acceleration = Vec3::Zero();
};

struct StartState {
  Vec3 position = Vec3::Zero();
  Vec3 velocity = Vec3::Zero();
  Vec3 acceleration = Vec3::Zero();
  bool from_plan = false;  // position and velocity are the last plan's
};

/// The start of the next plan: `last_plan` began `since_plan` seconds ago
/// (it covers now when 0 <= since_plan <= its duration; an empty plan
/// covers nothing; a stop covers all time after its start); `max_accel` caps
/// a measured acceleration.
StartState choose_start_state(const BsplineTrajectory& last_plan, LastPlan last_kind,
                              double since_plan, const MeasuredState& measured, double max_accel,
                              const StartStateSettings& settings);

}  // namespace ofn::rh
