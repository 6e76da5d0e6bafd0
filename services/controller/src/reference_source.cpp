#include "ofn/controller/reference_source.hpp"

namespace ofn::control {

const char* to_string(ControlMode mode) {
  switch (mode) {
    case ControlMode::kHold:
      return "HOLD";
    case ControlMode::kWaypoint:
      return "WAYPOINT";
    case ControlMode::kTrajectory:
      return "TRAJECTORY";
    case ControlMode::kNavStale:
      return "NAV_STALE";
    case ControlMode::kDone:
      return "DONE";
    case ControlMode::kSafeStop:
      return "SAFE_STOP";
  }
  return "UNKNOWN";
}

ReferenceChoice choose_reference(const StepSituation& s) {
  ReferenceChoice c;
  const ControlMode previous = s.previous;
  const bool before_flight = s.awaiting_planner && !s.fresh_plan &&
                             (previous == ControlMode::kHold || previous == ControlMode::kNavStale);
  if (!s.has_mission || before_flight) {
    c.source = ReferenceSource::kHold;
    c.mode = ControlMode::kHold;
    // A hold begins again wherever the vehicle is now: on entering it, on a
    // new mission (the vehicle may have been flown meanwhile) and after a
    // lapse.
    c.hold_begins = previous != ControlMode::kHold || s.mission_arrived || s.lapsed;
    // The control law begins again with it: what its integrators, networks
    // and actuator estimate hold was learnt against a reference the vehicle
    // was not flying (a simulated vehicle is frozen until the mission
    // comes; a real one is flown by its pilot). Carried over, the wound-up
    // command of the wait was flown on release and the vehicle surged.
    c.reset_control = c.hold_begins;
    return c;
  }
  c.reset_control = previous == ControlMode::kHold;
  if (s.fresh_plan) {
    c.source = ReferenceSource::kPlan;
    c.mode = ControlMode::kTrajectory;
  } else if (s.avoiding) {
    c.source = ReferenceSource::kPlanStop;
    c.mode = ControlMode::kSafeStop;
  } else if (previous != ControlMode::kDone && s.map_stale) {
    c.source = ReferenceSource::kBlindStop;
    c.mode = ControlMode::kSafeStop;
    // With no reference flown since navigation returned or the mission
    // arrived, the stop starts from the vehicle's own state.
    c.stop_from_vehicle = previous == ControlMode::kNavStale || !s.reference_flown;
  } else {
    c.source = ReferenceSource::kGuidance;
    c.mode = ControlMode::kWaypoint;
    c.end_stop = s.stopping;
    // Guidance resumes from the vehicle after any other reference: a plan,
    // a stop, or the hold flown while the planner's first word was awaited
    // (guidance was anchored when the mission came, and the vehicle has
    // flown the hold's stop since).
    c.resync_guidance = previous == ControlMode::kTrajectory ||
                        previous == ControlMode::kSafeStop || previous == ControlMode::kHold;
  }
  return c;
}

}  // namespace ofn::control
