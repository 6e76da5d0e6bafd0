#pragma once
// The controller process's settings and their config file
// (config/controller.yaml): the control law's gains, its nominal airframe,
// the reference selector, the command gate, guidance, the yaw sweep. No
// LCM: the service and the flight report (which judges the pseudo-control
// against the bound it gives) read the same file through it.

#include "ofn/common/config.hpp"
#include "ofn/controller/command_gate.hpp"
#include "ofn/controller/heading_reference.hpp"
#include "ofn/controller/neural_adaptation.hpp"
#include "ofn/controller/perception_watch.hpp"
#include "ofn/controller/reference_selector.hpp"
#include "ofn/controller/speed_reserve.hpp"
#include "ofn/controller/trajectory_controller.hpp"
#include "ofn/controller/waypoint_guidance.hpp"

namespace ofn::control {

struct ControllerConfig {
  double rate = 100.0;                 // Hz, control loop and ACTUATOR_CMD
  double status_rate = 50.0;           // Hz, CONTROL_STATUS
  double nav_timeout = 0.2;            // s; older navigation counts as lost
  double nav_prediction = 0.15;        // s; navigation up to this old is carried forward to now
  double ref_traj_timeout = 0.5;       // s; an older REF_TRAJ is no longer followed
  SelectorSettings selector;           // plan jumps refused; the stop when plans go stale
  PerceptionWatchSettings perception;  // guidance only on the planner's fresh word
  CommandGateSettings gate;            // airframe limits and geofence every command keeps
  ControllerGains gains;
  AdaptiveConfig adaptive;
  GuidanceConfig guidance;
  SpeedReserveSettings speed_reserve;  // speed kept back from the limit in gusts
  YawSweep sweep;
  PathHeading heading;
  vehicle::RotorcraftParams nominal;  // the controller's model of the airframe
};

ControllerConfig load_controller_config(YamlReader& reader);

}  // namespace ofn::control
