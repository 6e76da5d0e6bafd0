#pragma once
// A scenario file (YAML) describes one course: units, start state,
// waypoints, limits, timing gates and environment. Everything is converted
// to SI and world NED on load. See docs/SCENARIO_FORMAT.md.

#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "ofn/common/frames.hpp"
#include "ofn/common/mission_types.hpp"

namespace ofn {

/// One obstacle of the course, SI and world NED. Boxes stand on the ground
/// and may be yawed; cylinders and trees are vertical.
struct ObstacleSpec {
  enum class Kind { kBox, kCylinder, kTree };
  Kind kind = Kind::kBox;
  int id = 0;                    // unique within the scenario, from 1
  double north = 0, east = 0;    // m, centre of the footprint
  double length = 0, width = 0;  // m; box: along its x / y; cylinder: diameter, diameter;
                                 // tree: canopy extent along north / east
  double height = 0;             // m above ground (tree: canopy top)
  double yaw = 0;                // rad from north, positive to the east (boxes only)
  int seed = 0;                  // tree canopy shape
  double appear_time = -1;       // s after the start; negative: present from the start
  double disappear_time = -1;    // s after the start; negative: never removed

  /// Present at t (s after the start): from appear_time (inclusive) until
  /// disappear_time (exclusive).
  bool present_at(double t) const {
    return (appear_time < 0 || t >= appear_time) && (disappear_time < 0 || t < disappear_time);
  }
};

/// The airframe as flown, relative to the model the controller assumes
/// (vehicle_sim's configured airframe), and its actuator authority. The
/// defaults leave the airframe as configured.
struct VehicleVariation {
  double mass_scale = 1.0;
  Vec3 inertia_scale = Vec3::Ones();  // roll, pitch, yaw
  double actuator_time_scale = 1.0;   // servo lag and rotor flapping time constants
  // Actuator authority; unset: the airframe's own. rad and rad/s.
  std::optional<double> collective_min, collective_max;
  std::optional<double> cyclic_limit, pedal_limit;  // symmetric, +-
  std::optional<double> collective_rate, cyclic_rate, pedal_rate;
};

/// Dryden turbulence (MIL-F-8785C, low-altitude form). Intensity either from
/// the wind speed at 20 ft (light 15 kt, moderate 30 kt, severe 45 kt) or
/// explicit; scale lengths from the altitude unless explicit.
struct TurbulenceSpec {
  double wind_at_20ft = 0;           // m/s; 0 and no explicit sigma: no turbulence
  std::optional<Vec3> sigma;         // m/s along the flight path (u), across it (v), down (w)
  std::optional<Vec3> scale_length;  // m, L_u, L_v, L_w
  bool active() const { return wind_at_20ft > 0 || (sigma && sigma->norm() > 0); }
};

/// Errors of the navigation solution: white noise on what NAV_STATE reports
/// and its age when it is published.
struct NavErrorSpec {
  double position_sigma = 0;  // m, per axis
  double velocity_sigma = 0;  // m/s, per axis
  double attitude_sigma = 0;  // rad, per axis (small rotation)
  double rate_sigma = 0;      // rad/s, per axis
  double latency = 0;         // s
};

struct Disturbances {
  TurbulenceSpec turbulence;
  NavErrorSpec nav;
  uint32_t seed = 1;  // turbulence and nav-noise random stream
};

struct Scenario {
  std::string name;
  std::string description;
  std::string file;
  std::string display_unit = "m";  // unit the file was written in, used for reports
  double metres_per_unit = 1.0;

  Vec3 start_position = Vec3::Zero();  // m, world NED
  Vec3 start_velocity = Vec3::Zero();  // m/s, world NED
  double start_heading = 0;            // rad from north

  std::vector<Waypoint> waypoints;
  double cruise_speed = 0;  // m/s
  Limits limits;

  /// North coordinates (m) of the timing gate lines; the clock starts at the
  /// first crossing of start_gate and stops at the first of finish_gate.
  std::optional<double> start_gate;
  std::optional<double> finish_gate;

  std::vector<ObstacleSpec> obstacles;
  double ground_altitude = 0;  // m; the flat ground is the plane z = -ground_altitude

  Vec3 wind = Vec3::Zero();  // m/s, world NED, velocity of the air mass
  double max_time = 600;     // s of simulated time before a run is abandoned

  VehicleVariation vehicle;   // `vehicle:` section
  Disturbances disturbances;  // `disturbances:` section
};

/// Loads and checks a scenario; throws ConfigError naming the file and field.
Scenario load_scenario(const std::string& path);

}  // namespace ofn
