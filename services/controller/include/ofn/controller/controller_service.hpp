#pragma once
// Binds guidance and the trajectory follower to the bus. Chooses the
// reference each step: a fresh REF_TRAJ (avoidance) overrides nominal
// waypoint guidance; without a mission the vehicle holds position; without
// fresh navigation it commands a level hover.

#include <optional>

#include "ofn/common/node.hpp"
#include "ofn/control_status_t.hpp"
#include "ofn/controller/command_gate.hpp"
#include "ofn/controller/controller_config.hpp"
#include "ofn/controller/heading_reference.hpp"
#include "ofn/controller/neural_adaptation.hpp"
#include "ofn/controller/perception_watch.hpp"
#include "ofn/controller/reference_selector.hpp"
#include "ofn/controller/speed_reserve.hpp"
#include "ofn/controller/trajectory_controller.hpp"
#include "ofn/controller/waypoint_guidance.hpp"
#include "ofn/mission_t.hpp"
#include "ofn/nav_state_t.hpp"
#include "ofn/ref_traj_t.hpp"
#include "ofn/scanner_status_t.hpp"
#include "ofn/solver_stats_t.hpp"

namespace ofn::control {

/// Reference from a REF_TRAJ at time t (seconds after its t0), by linear
/// interpolation of its samples; nullopt outside the sampled span.
std::optional<Reference> sample_ref_traj(const ref_traj_t& traj, Utime now);

class ControllerService {
 public:
  ControllerService(lcm::LCM& lcm, const Clock& clock, ControllerConfig config);
  Node& node() { return node_; }
  int8_t mode() const { return mode_; }
  bool sweeping() const { return sweeping_; }

 private:
  void on_nav(const nav_state_t& m) { nav_ = m; }
  void on_solver_stats(const solver_stats_t& m);
  void on_mission(const mission_t& m);
  // A NOMINAL trajectory hands back to waypoint guidance. Avoidance, a kept
  // previous plan and braking override it (paper 2.1), if they start on the
  // reference flown now or on the vehicle.
  void on_ref_traj(ref_traj_t m);
  void on_scanner_status();
  /// The mission's limits; the airframe's before any mission.
  Limits flight_limits() const;
  void control_step();
  void publish_status();
  double yaw_reference(const std::optional<Vec3>& facing, double horizontal_speed, double dt,
                       double* yaw_rate);

  Node node_;
  ControllerConfig config_;
  TrajectoryController controller_;
  WaypointGuidance guidance_;
  SpeedReserve speed_reserve_;
  bool keeping_reserve_ = false;  // for the log: a reserve is kept back now
  ReferenceSelector selector_;
  PerceptionWatch perception_;
  CommandGate gate_;
  std::optional<nav_state_t> nav_;
  std::optional<mission_t> mission_;
  bool mission_pending_ = false;
  std::optional<ref_traj_t> ref_traj_;
  int8_t mode_ = control_status_t::NAV_STALE;  // until the first navigation arrives
  PathHeadingFilter path_heading_;
  Reference last_ref_;
  bool last_ref_flown_ = false;
  Utime last_flown_step_ = INT64_MIN;  // when last_ref_ was flown
  ControlOutput last_out_;
  Utime last_step_ = INT64_MIN;
  Utime last_scan_ = INT64_MIN;
  YawSweepGenerator sweep_;
  bool sweeping_ = false;
};

}  // namespace ofn::control
