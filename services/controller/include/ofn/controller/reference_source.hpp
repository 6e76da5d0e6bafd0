#pragma once
// The control loop's mode machine: which reference the controller flies
// this step, given what it knows (mission, navigation already checked fresh,
// the planner's word, the avoidance plan), and how that reference begins.
// The service evaluates the inputs, asks choose_reference() and carries the
// choice out (ReferenceSelector, WaypointGuidance); the rules live here so
// that each can be tested without a bus. In order:
//  1. HOLD: no mission, or a mission whose flight has not begun (the
//     planner has never confirmed the way on a fresh map, no plan is being
//     flown, and the controller held or had no navigation before);
//  2. TRAJECTORY: a fresh avoidance plan covers the present;
//  3. SAFE_STOP from the plan: avoidance had overridden guidance and its
//     plan went stale (a dead, stopped or cut-off optimiser): the plan's
//     stop, then the hover, never guidance along the blocked leg;
//  4. SAFE_STOP, guidance held: guidance would fly the leg without a fresh
//     map (unless the mission is done): a stop, then the hover;
//  5. WAYPOINT (DONE at the last waypoint, which guidance decides):
//     waypoint guidance.
// Navigation lost (NAV_STALE) is decided before any of this: without a
// fresh navigation solution there is no reference at all.
// Pure core, no bus; the modes are CONTROL_STATUS's values.

#include <cstdint>

namespace ofn::control {

/// CONTROL_STATUS's modes (the service checks that the values agree).
enum class ControlMode : int8_t {
  kHold = 0,
  kWaypoint = 1,
  kTrajectory = 2,
  kNavStale = 3,
  kDone = 4,
  kSafeStop = 5
};

const char* to_string(ControlMode mode);

/// Where the step's reference comes from.
enum class ReferenceSource {
  kHold,       // the hold: the stop from the vehicle's state, then the hover there
  kPlan,       // the avoidance plan (REF_TRAJ)
  kPlanStop,   // the stale avoidance plan's stop, then the hover
  kBlindStop,  // guidance held without a fresh map: a stop, then the hover
  kGuidance    // waypoint guidance (WAYPOINT, or DONE once it says so)
};

struct StepSituation {
  ControlMode previous = ControlMode::kNavStale;  // the last step's mode
  bool has_mission = false;
  bool mission_arrived = false;  // a new mission was taken up this step
  bool lapsed = false;           // no reference flown for a while: restart from the vehicle
  /// A reference was flown on the last step and may be carried on (false
  /// after a lapse or a new mission).
  bool reference_flown = false;
  /// The planner's word on a fresh map is awaited before the flight begins
  /// (perception watching is enabled and it has never confirmed).
  bool awaiting_planner = false;
  bool fresh_plan = false;  // an avoidance plan within its timeout covers the present
  bool avoiding = false;    // avoidance has overridden guidance and not handed back
  bool map_stale = false;   // the planner's word or its map is stale (PerceptionWatch)
  bool stopping = false;    // a stop is being flown (ReferenceSelector::stopping)
};

struct ReferenceChoice {
  ReferenceSource source = ReferenceSource::kHold;
  /// The mode to report; for kGuidance, kWaypoint until guidance says the
  /// mission is done.
  ControlMode mode = ControlMode::kHold;
  bool hold_begins = false;        // kHold: a new hold from the vehicle's state
  bool stop_from_vehicle = false;  // kBlindStop: from the vehicle, not the reference flown
  bool end_stop = false;           // kGuidance: the stop flown until now has ended
  bool resync_guidance = false;    // kGuidance: guidance restarts from the vehicle
  bool reset_control = false;      // a hold begins or is left: the control law begins again
};

ReferenceChoice choose_reference(const StepSituation& s);

}  // namespace ofn::control
