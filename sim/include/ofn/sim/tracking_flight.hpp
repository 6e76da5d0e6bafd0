#pragma once
// A course flown in-process: the simulated vehicle (airframe variation,
// wind, turbulence, navigation errors from the scenario) and the trajectory
// follower stepped together under waypoint guidance, with no bus. Measures
// how well the vehicle follows the commanded trajectory; used by the
// adaptive-control tests, benchmarks and the tracking sweep. Pure core: no
// LCM, no clock. It gives the follower its reference and heading as the
// controller service does in waypoint mode, without the service's other
// modes, command gate, speed governor or held adaptation.

#include <vector>

#include "ofn/common/scenario.hpp"
#include "ofn/controller/heading_reference.hpp"
#include "ofn/controller/neural_adaptation.hpp"
#include "ofn/controller/trajectory_controller.hpp"
#include "ofn/controller/waypoint_guidance.hpp"
#include "ofn/rotorcraft_model/rotorcraft_model.hpp"

namespace ofn::sim {

struct TrackingFlightConfig {
  double duration = 600;      // s of flight
  double control_rate = 100;  // Hz
  double physics_rate = 400;  // Hz
  bool round_trip = true;     // at the last waypoint, fly the route back, until `duration`
  bool yaw_sweep = true;      // the scanner's yaw sweep (TrackingSetup::sweep)
  double settle_time = 5;     // s at the start left out of the error statistics
  double trace_interval = 1;  // s between samples of the traces
};

struct TrackingResult {
  double rms_error = 0;  // m, commanded position - true position
  double max_error = 0;  // m
  double rms_error_first_half = 0, rms_error_second_half = 0;
  double max_weight_norm = 0, final_weight_norm = 0;
  bool all_valid = true;          // no step fell back to the safe command
  bool all_within_limits = true;  // every command within the nominal actuator limits
  bool finite = true;             // the vehicle's state stayed finite
  int legs_flown = 0;
  std::vector<double> weight_norm_trace;  // every trace_interval
  std::vector<double> error_trace;        // m, every trace_interval
};

struct TrackingSetup {
  vehicle::RotorcraftParams nominal;  // the controller's model; the flown airframe is this
                                      // changed by the scenario's `vehicle:` section
  control::ControllerGains gains;
  control::AdaptiveConfig adaptive;
  control::GuidanceConfig guidance;
  // The heading as the controller service commands it: along the leg at a
  // bounded turn rate (a route flown back turns it through 180 deg), with
  // the yaw sweep over it.
  control::PathHeading heading;
  control::YawSweep sweep;
  /// Of the scenario's acceleration limit: the stop whose distance the sweep
  /// covers (the controller's reference_selector.stop_accel_fraction).
  double stop_accel_fraction = 0.8;
  /// s; navigation up to this old is carried forward to now (the
  /// controller's nav_prediction; 0: used as it comes).
  double nav_prediction = 0.15;
};

/// Flies the scenario's waypoints (steady wind, disturbances, airframe
/// variation all from the scenario).
TrackingResult fly_tracking(const Scenario& scenario, const TrackingSetup& setup,
                            const TrackingFlightConfig& config = {});

}  // namespace ofn::sim
