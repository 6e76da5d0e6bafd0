#pragma once
// Binds the rotorcraft model and the LIDAR head to the bus: ACTUATOR_CMD,
// CONTROL_STATUS and VIRTUAL_OBSTACLES in; NAV_STATE, SIM_CLOCK and LIDAR_RAW
// out. Physics and the scanner run on a fixed-step timer of the node's clock.
// The scenario sets the airframe's deviation from the configured one, the
// wind and turbulence, and the navigation solution's noise and latency.
// When ACTUATOR_CMD stops, the airframe's own stabiliser flies it
// (AirframeFailsafe) until commands come again.

#include <functional>
#include <optional>
#include <string>

#include "ofn/actuator_cmd_t.hpp"
#include "ofn/common/config.hpp"
#include "ofn/common/node.hpp"
#include "ofn/common/scenario.hpp"
#include "ofn/control_status_t.hpp"
#include "ofn/vehicle_sim/airframe_failsafe.hpp"
#include "ofn/vehicle_sim/checkpoint.hpp"
#include "ofn/vehicle_sim/disturbances.hpp"
#include "ofn/vehicle_sim/lidar_head.hpp"
#include "ofn/vehicle_sim/rotorcraft_simulation.hpp"
#include "ofn/virtual_obstacles_t.hpp"
#include "ofn/world/world.hpp"

namespace ofn::vehicle {

struct VehicleSimConfig {
  double physics_rate = 400.0;  // Hz, fixed integration step
  double nav_rate = 100.0;      // Hz, NAV_STATE and SIM_CLOCK
  /// s without a valid ACTUATOR_CMD before the airframe's stabiliser takes
  /// over (armed by the first command; the heartbeat then says
  /// "failsafe"); 0: no failsafe, the airframe flies the last command.
  double command_timeout = 0.2;
  /// Hold the vehicle in trimmed flight at its start state (the clock still
  /// runs) until the controller reports a mission (it then commands the
  /// vehicle in every mode), as a flight test begins when the autopilot is
  /// engaged.
  bool hold_until_engaged = true;
  /// Release the hold after this long anyway (s of clock time).
  double engage_timeout = 10.0;
  /// s of clock time between checkpoints (set_checkpoint_sink).
  double checkpoint_period = 0.1;
  RotorcraftParams params;
  LidarConfig lidar;
};

/// Reads a vehicle_sim config; unknown fields are errors.
VehicleSimConfig load_vehicle_sim_config(YamlReader& reader);

class VehicleSimService {
 public:
  using CheckpointSink = std::function<void(const VehicleCheckpoint&)>;

  /// `resume`: go on with a saved flight (its state, time and release)
  /// rather than start the scenario's; the clock must start at its time.
  VehicleSimService(lcm::LCM& lcm, const Clock& clock, const Scenario& scenario,
                    VehicleSimConfig config, double real_time_factor = 1.0,
                    std::optional<VehicleCheckpoint> resume = std::nullopt);

  /// Called with the flight's state every checkpoint_period of clock time
  /// (main writes it to a file); what it throws is logged, and the flight
  /// goes on.
  void set_checkpoint_sink(CheckpointSink sink);

  Node& node() { return node_; }
  const RotorcraftSimulation& model() const { return vehicle_.model(); }
  const SimulatedVehicle& vehicle() const { return vehicle_; }
  bool released() const { return released_; }
  const world::World& world() const { return world_; }
  const LidarHead& lidar() const { return lidar_; }
  int64_t scans_published() const { return scans_published_; }
  const AirframeFailsafe& failsafe() const { return failsafe_; }

 private:
  void on_command(const actuator_cmd_t& msg);
  void on_control_status(const control_status_t& msg);
  void on_virtual_obstacles(const virtual_obstacles_t& msg);
  void publish_scan(const LidarScan& scan);
  void step_physics();
  void publish_nav();

  Node node_;
  VehicleSimConfig config_;
  double real_time_factor_;
  SimulatedVehicle vehicle_;
  AirframeFailsafe failsafe_;
  RotorcraftState start_state_;
  Controls trim_controls_;
  Utime state_time_ = INT64_MIN;
  Utime last_command_time_ = INT64_MIN;
  Utime hold_started_ = INT64_MIN;
  bool released_ = false;
  int64_t steps_ = 0;
  world::World world_;
  LidarHead lidar_;
  int32_t obstacle_revision_ = -1;
  int64_t scans_published_ = 0;
  std::optional<VehicleCheckpoint> resume_;
  CheckpointSink checkpoint_sink_;
  Utime last_checkpoint_ = INT64_MIN;
  bool checkpoint_failing_ = false;
};

}  // namespace ofn::vehicle
