#pragma once
// Binds the RH optimiser to the bus (paper 2.2): NAV_STATE, MISSION,
// OBSTACLE_GRID, GLOBAL_PATH, SCAN_WORLD and CONTROL_STATUS in; REF_TRAJ and
// SOLVER_STATS out at a fixed rate, and NARROW_PASSAGES (passages of the
// global route it found it cannot fly) for the global planner. It builds the
// distance field from the grid and the record of seen space from the scans;
// every decision (engage, hand back, recovery, defer, what is published and
// as what mode) is the AvoidanceSupervisor's, whose decision this class
// turns into messages and log lines.

#include <optional>
#include <string>
#include <vector>

#include "ofn/common/config.hpp"
#include "ofn/common/node.hpp"
#include "ofn/common/warning_streak.hpp"
#include "ofn/control_status_t.hpp"
#include "ofn/global_path_t.hpp"
#include "ofn/map/distance_field.hpp"
#include "ofn/map/heightfield.hpp"
#include "ofn/mission_t.hpp"
#include "ofn/narrow_passages_t.hpp"
#include "ofn/nav_state_t.hpp"
#include "ofn/obstacle_grid_t.hpp"
#include "ofn/ref_traj_t.hpp"
#include "ofn/rh_optimizer/avoidance_supervisor.hpp"
#include "ofn/rh_optimizer/occlusion.hpp"
#include "ofn/scan_world_t.hpp"
#include "ofn/solver_stats_t.hpp"

namespace ofn::rh {

struct RhOptimizerServiceConfig {
  double rate = 10.0;                  // Hz, one receding-horizon step per tick (paper: 5-20 Hz)
  double nav_max_age = 0.5;            // s; older NAV_STATE is stale
  double grid_max_age = 1.0;           // s; older OBSTACLE_GRID is stale: no avoidance decisions
  double path_max_age = 5.0;           // s; an older GLOBAL_PATH is not used as a guess
  double sample_period = 0.0;          // s between REF_TRAJ samples; 0: the spline alone
  double route_change_distance = 5.0;  // m a new global path must differ by to be a new route
  double field_period = 0.2;           // s; the distance field is rebuilt at most this often
  double field_altitude_band = 40.0;   // m of altitude above and below the vehicle in the field
  double occlusion_depth =
      30.0;  // m of hidden space behind a seen face taken as obstacle (0: none)
  double visibility_band =
      3.0;  // m around flight altitude in which a crossing beam counts as a look
  /// m into unseen space beside an obstacle taken as obstacle of unknown
  /// height (extend_into_unseen; 0: none; needs occlusion_depth > 0, which
  /// turns the visibility record on). Off by default: at 3 m it removed the
  /// dense fields' clearance violation but cost completeness, forward-speed
  /// excursions and course time (docs/TUNING.md).
  double unseen_extension = 0.0;
  /// Unseen cells from `unseen_near_exempt` to `unseen_near_reach` m of the
  /// vehicle taken as obstacle of unknown height (raise_unseen_near; 0:
  /// none; needs occlusion_depth > 0): beside the path, where the sweep
  /// has not looked, the optimiser plans R_s + clearance_margin from them
  /// and the commit gate's stops 0.9 R_s (dense seed 412 passed an unseen
  /// cylinder at 0.78 R_s). The exempt disc keeps the vehicle's own
  /// position outside them: its cell squares stay more than 0.5 R_s away,
  /// where the optimiser still solves (start_inside_fraction). At 10 m
  /// every flight starts by braking to look round itself (the scanner has
  /// seen a narrow wedge ahead), and the lockstep runner takes about twice
  /// the CPU (docs/TUNING.md).
  double unseen_near_reach = 10.0;
  double unseen_near_exempt = 4.0;
  bool planned_initial_acceleration = true;  // a(t0) from the last plan, not the nav solution
  /// Position and velocity at t0 from the last plan too, while the vehicle
  /// is within these errors of it. Starting every plan at the measured
  /// state would reset the controller's reference to the vehicle ten times
  /// a second: its feedback never acts, and each lag behind a manoeuvre
  /// is accepted into the next plan (the vehicle slowed to half speed
  /// topping bench1's wall while every plan said full speed).
  bool planned_initial_state = true;
  double replan_position_error = 3.0;  // m; farther from the plan, start from the vehicle
  double replan_velocity_error = 1.5;  // m/s
  /// A stop is held while the vehicle is within this of it (start_state.hpp).
  double stop_recapture_error = 6.0;  // m
  // Before a first avoidance trajectory exists, a failed solve brakes only
  // if the conflict is within braking distance plus this; otherwise nominal
  // guidance continues (DEFERRED) and the next tick tries again, typically
  // with the global route that the new obstacle is about to produce.
  double defer_margin = 10.0;  // m
  mapping::DistanceFieldConfig field;
  /// Flown with reserves on the speed and acceleration limits, a smaller
  /// clearance margin than the core's plain defaults, and equal weights (Eq.
  /// 1 becomes the squared distance to the target, so past an obstacle the
  /// path heads for the waypoint instead of back to the leg first): measured
  /// on the benchmark courses (README, "Planning and avoidance").
  RhSettings optimizer = [] {
    RhSettings s;
    s.weights = Vec3(30.0, 30.0, 30.0);
    s.speed_margin = 0.005;
    s.accel_margin = 0.06;
    s.forward_speed_reserve = 0.15;
    s.clearance_margin = 0.5;
    return s;
  }();
  FallbackSettings fallback;
  CommitSettings commit;  // the safety invariant of every published plan
  SwitchSettings avoidance;
  RecoverySettings recovery;           // out of dead ends
  PassageSettings passages;            // routes through gaps too narrow to fly, told to the planner
  ScanSupplySettings scan_supply;      // no plans on a map starved of scans
  TrackingTubeSettings tracking_tube;  // clearances widened by the tracking error
};

/// Reads an rh_optimizer config; unknown fields are errors.
RhOptimizerServiceConfig load_rh_optimizer_config(YamlReader& reader);

/// The grid as a heightfield, padded with free cells so that the distance
/// field (which holds its boundary values beyond its edges) reads
/// `pad_distance` or more away from the obstacles.
mapping::Heightfield padded_heightfield(const obstacle_grid_t& grid, double pad_distance);

/// REF_TRAJ of a trajectory: the spline and samples every `period` seconds.
ref_traj_t trajectory_message(const BsplineTrajectory& trajectory, Utime t0, int8_t mode,
                              double period, Utime utime);

/// NARROW_PASSAGES of a mission's passages.
narrow_passages_t passages_message(const std::vector<NarrowPassage>& passages, int32_t mission_id,
                                   Utime utime);

class RhOptimizerService {
 public:
  RhOptimizerService(lcm::LCM& lcm, const Clock& clock, RhOptimizerServiceConfig config);
  Node& node() { return node_; }
  bool engaged() const { return supervisor_.engaged(); }
  int64_t steps() const { return supervisor_.steps(); }

 private:
  void on_nav(const nav_state_t& m) { nav_ = m; }
  void on_mission(const mission_t& m);
  void on_grid(const obstacle_grid_t& m);
  void on_global_path(const global_path_t& m);
  void on_scan(const scan_world_t& m);
  /// The controller's active leg (LegTracker::follow) and its position
  /// error (the tracking tube).
  void on_control_status(const control_status_t& m);
  /// One decision of the supervisor, published and logged.
  void tick();
  /// Brings the distance field up to date for a tick that plans.
  MapView refresh_field(Utime now, const Vec3& vehicle);
  void publish_nominal(Utime now, const Vec3& position, const Vec3& velocity);
  /// The mission's passages, for the global planner (on change and 1 Hz).
  void publish_passages(Utime now);
  void log_lines(const std::vector<LogLine>& lines);
  /// `guidance_clear`: the nominal leg was checked on the current field and
  /// waypoint guidance may fly it (the controller's PerceptionWatch).
  void publish_stats(Utime now, const SupervisorDecision& decision);

  Node node_;
  RhOptimizerServiceConfig config_;
  AvoidanceSupervisor supervisor_;
  std::optional<nav_state_t> nav_;
  std::optional<mission_t> mission_;
  std::optional<obstacle_grid_t> grid_;
  bool grid_dirty_ = false;
  VisibilityRecord visibility_;
  ShadowMemory shadows_;
  int64_t scans_seen_ = 0;
  mapping::Heightfield heightfield_;
  // heightfield_ before the shadows: what the unseen extension starts from
  mapping::Heightfield mapped_;
  mapping::DistanceField field_;
  bool field_valid_ = false;
  Utime field_built_ = INT64_MIN;
  // The stamp of the grid the field was built from (SOLVER_STATS.map_utime).
  Utime field_map_utime_ = 0;
  double field_altitude_ = 0;  // vehicle altitude the field's band is centred on
  // Failed steps are logged once per streak (common/warning_streak.hpp).
  WarningStreak warning_streak_{"worst violation"};
  std::string last_note_;
};

}  // namespace ofn::rh
