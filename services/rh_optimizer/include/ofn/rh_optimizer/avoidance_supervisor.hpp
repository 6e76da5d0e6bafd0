#pragma once
// The RH optimiser's decisions, one tick at a time (paper 2.1-2.2): whether
// a tick plans at all (a mission, fresh navigation, a leg, a fresh map fed
// by the scanner), when avoidance takes over from waypoint guidance and
// when it hands back (AvoidanceSwitch), what a dead end calls for
// (DeadEndRecovery: a hover to look or turn, an escape framed from where it
// began, a climb), where a plan starts (choose_start_state) and what it
// solves (leg_problem, frame_escape, RhPlanner), whether a first failed
// step is deferred to guidance (defer_first_brake, only before anything is
// published), and what goes out: nothing, SOLVER_STATS alone, a NOMINAL
// trajectory, a hover or a plan, each with its mode.
//
// It owns the state those decisions carry from tick to tick (the planner's
// warm start, the last plan flown, the switch, the recovery, the leg, the
// routes, the narrow passages found, the scan supply and the tracking
// tube) and knows no messages: the caller (RhOptimizerService) translates
// messages into the calls below, publishes what a decision says and logs
// its lines. The map is the caller's (the distance field and the record of
// seen space): a tick that plans asks for it once (TickInput::map).
//
// Pure core: world NED, SI; clock time as microsecond stamps (Utime,
// ofn/common/time.hpp) where ages and a plan's elapsed time are taken, so
// that they are the same integer differences a service computes, and in
// seconds (to_seconds) for everything handed on.

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "ofn/common/frames.hpp"
#include "ofn/common/leg_tracker.hpp"
#include "ofn/common/mission_types.hpp"
#include "ofn/common/time.hpp"
#include "ofn/map/heightfield.hpp"
#include "ofn/rh_optimizer/avoidance_switch.hpp"
#include "ofn/rh_optimizer/commit_gate.hpp"
#include "ofn/rh_optimizer/dead_end_recovery.hpp"
#include "ofn/rh_optimizer/narrow_passage.hpp"
#include "ofn/rh_optimizer/rh_planner.hpp"
#include "ofn/rh_optimizer/scan_supply.hpp"
#include "ofn/rh_optimizer/start_state.hpp"
#include "ofn/rh_optimizer/tracking_tube.hpp"

namespace ofn::rh {

struct SupervisorSettings {
  double rate = 10.0;                  // Hz of tick(): NOMINAL is repeated every ceil(rate) ticks
  double nav_max_age = 0.5;            // s; older navigation is stale: no decisions
  double grid_max_age = 1.0;           // s; an older obstacle grid is stale: no decisions
  double path_max_age = 5.0;           // s; an older global route is no guess
  double route_change_distance = 5.0;  // m a new route must differ by to be a new route
  /// m beyond the stop from the speed flown within which a first failed step
  /// brakes; farther off it is deferred (defer_first_brake).
  double defer_margin = 10.0;
  StartStateSettings start;
  RhSettings optimizer;
  FallbackSettings fallback;
  CommitSettings commit;
  SwitchSettings avoidance;
  RecoverySettings recovery;
  PassageSettings passages;
  ScanSupplySettings scan_supply;
  TrackingTubeSettings tracking_tube;
};

/// The navigation solution a tick decides on.
struct NavInput {
  Utime utime = 0;  // its stamp
  Vec3 position = Vec3::Zero();
  Vec3 velocity = Vec3::Zero();
  Vec3 acceleration = Vec3::Zero();
  double yaw = 0;  // rad, the heading
};

/// The map the plans are made on, brought up to date by the caller.
struct MapView {
  /// The obstacle tops (padded, with the shadows of occlusion): the
  /// horizon (terminal_x) and an escape's end are found on it. Required.
  const mapping::Heightfield* heightfield = nullptr;
  ClearanceQuery clearance;  // the distance field over it. Required.
  SeenQuery seen;            // cells seen free; empty: no record of seen space
};

struct TickInput {
  Utime now = 0;
  std::optional<NavInput> nav;      // none before the first navigation message
  std::optional<Utime> grid_utime;  // stamp of the newest obstacle grid; none before one
  /// Called once, only when the tick goes on to decide on the map (a
  /// mission, fresh navigation, a leg, a fresh grid and a map fed by the
  /// scanner): the caller brings its map up to date there, so that it is
  /// rebuilt on the ticks that plan and only on them.
  std::function<MapView()> map;
};

/// A global route as the planner published it.
struct RouteInput {
  Utime utime = 0;
  RouteKind kind = RouteKind::kNone;
  std::vector<Vec3> points;  // world NED, vehicle first (as published; none for kNoPath)
  /// It may serve as the optimiser's cold-start guess: a route that leads
  /// on (also one too sharp to fly at cruise speed) with two points or more.
  bool guess = false;
};

/// SOLVER_STATS' status of a decision.
enum class StatsStatus {
  kNotRun,
  kSolved,
  kKeptPrevious,
  kBraking,
  kDeferred,
  kLookingAround,
  kNoRoute
};
/// REF_TRAJ's mode of a trajectory decided on: a solved plan, the previous
/// one kept, a stop, a hover (or a climb) while the heading turns to the
/// right or to the left.
enum class PlanMode { kAvoidance, kPrevious, kBraking, kLookAround, kLookAroundLeft };

struct LogLine {
  enum class Level { kInfo, kWarn };
  Level level = Level::kInfo;
  std::string text;
};

/// A failed step, for the log's streak of like warnings (WarningStreak):
/// `kind` names it without numbers, `text` says it in full.
struct StepWarning {
  std::string kind;
  std::string text;
  double figure = 0;  // the step's worst constraint violation
};

struct SupervisorDecision {
  enum class Publish {
    kNothing,  // no mission, no navigation or no leg yet
    kStats,    // SOLVER_STATS alone
    kNominal,  // a NOMINAL trajectory from the navigation state (guidance flies), then the stats
    kHover,    // a recovery's hover (trajectory, mode), then the stats
    kStep,     // a planner step's plan or stop (trajectory, mode), then the stats
  };
  Publish publish = Publish::kNothing;
  std::string state;  // what the optimiser is doing, for its heartbeat
  /// A narrow passage was found this tick: the passages (passages()) go out
  /// before anything else.
  bool passages_changed = false;
  // kHover, kStep:
  BsplineTrajectory trajectory;  // world NED
  Utime t0 = 0;                  // clock time of its t = 0
  PlanMode mode = PlanMode::kBraking;
  /// kStep: the guidance frame the step was solved in (the leg's, or an
  /// escape's, from where the escape began towards its end).
  GuidanceFrame frame = GuidanceFrame::from_leg(Vec3::Zero(), Vec3::UnitX());
  // Every publish but kNothing:
  StatsStatus status = StatsStatus::kNotRun;
  std::string message;                 // with the recovery's mark (recovery_message)
  std::optional<SolveReport> report;   // the step's last solve, when a step ran
  bool guidance_clear = false;         // the nominal leg was checked clear on the map
  std::vector<LogLine> log;            // in order
  std::optional<StepWarning> warning;  // a step that did not solve; none: the streak ends
};

/// Largest distance from a point of `b` (over its first `horizon` metres
/// from `from`) to the polyline `a`: how much two routes differ where it
/// matters (infinity when either is empty).
double route_difference(const std::vector<Vec3>& a, const std::vector<Vec3>& b, const Vec3& from,
                        double horizon);

class AvoidanceSupervisor {
 public:
  /// Throws std::invalid_argument for settings RhPlanner refuses.
  explicit AvoidanceSupervisor(SupervisorSettings settings = {});

  /// A new mission (id, waypoints, limits in SI): every leg, plan, switch
  /// state and narrow passage of the last one is forgotten.
  void start_mission(int mission_id, std::vector<Waypoint> waypoints, const Limits& limits);
  /// A global route. `vehicle`: where the vehicle is, if known (the route's
  /// difference from the last is judged from there). Returns the lines to
  /// log.
  std::vector<LogLine> route(const RouteInput& route, const std::optional<Vec3>& vehicle);
  /// The controller flies to waypoint `index` of mission `mission_id`
  /// (LegTracker::follow).
  void controller_leg(int mission_id, int index) { legs_.follow(mission_id, index); }
  /// The controller's position error at `time` (s) while it flies a
  /// reference (the tracking tube).
  void tracking_error(double time, const Vec3& error) { tube_.add(time, error); }
  /// A scan numbered `index` reached the map's record at `time` (s).
  void scan_received(double time, int64_t index) { scan_supply_.received(time, index); }

  /// One decision (the service's timer, `rate` Hz).
  SupervisorDecision tick(const TickInput& in);

  bool engaged() const { return switch_.engaged(); }
  int64_t steps() const { return steps_; }
  /// Index of the waypoint that ends the leg decided on (-1 before one).
  int active_leg() const { return active_leg_; }
  RecoveryPhase recovery_phase() const { return recovery_.phase(); }
  /// The mission's passages found too narrow to fly, for the global planner.
  const std::vector<NarrowPassage>& passages() const { return passages_.passages(); }
  const SupervisorSettings& settings() const { return settings_; }

 private:
  /// `d` publishing `publish`, its SOLVER_STATS `status` and `message`
  /// (marked by the recovery's phase), the optimiser's state `state`.
  SupervisorDecision& with_stats(SupervisorDecision& d, SupervisorDecision::Publish publish,
                                 StatsStatus status, const std::string& message,
                                 const std::string& state) const;
  /// The clearance a route's pinches and stops are checked for: what the
  /// optimiser accepts as feasible.
  double pinch_clearance(const Limits& limits) const;
  /// m the safety radius is widened by now (TrackingTube); a line when it
  /// changes by a quarter metre or more.
  double tracking_widening(Utime now, std::vector<LogLine>* log);
  /// The route the recovery is about to take after a look: a new pinch on
  /// it, or no room to stop at the corner its escape would stop at, is
  /// remembered, so that the planner's next route goes another way. True if
  /// one was.
  bool check_route_for_pinch(Utime now, const Limits& limits, const GuidanceFrame& leg,
                             const ClearanceQuery& clearance, SupervisorDecision* d);
  RecoveryDecision update_recovery(Utime now, const Leg& leg, const Limits& limits,
                                   const NavInput& nav, bool engaged,
                                   const ClearanceQuery& clearance, const SeenQuery& seen,
                                   SupervisorDecision* d);
  /// Forgets the planner's previous plan, the last published one and the
  /// engagement's stop and stall flags (a new mission, a hand-back).
  void restart_planning();
  /// The decision of a tick that plans, on the map.
  SupervisorDecision& decide(SupervisorDecision& d, Utime now, const NavInput& nav,
                             const ActiveLeg& active, const MapView& map);

  SupervisorSettings settings_;
  RhPlanner planner_;
  AvoidanceSwitch switch_;
  DeadEndRecovery recovery_;
  PassageMemory passages_;
  ScanSupply scan_supply_;
  TrackingTube tube_;
  LegTracker legs_;
  // The mission (start_mission).
  bool has_mission_ = false;
  int mission_id_ = -1;
  std::vector<Waypoint> waypoints_;
  Limits limits_;
  int active_leg_ = -1;
  bool scans_starved_ = false;
  double logged_widening_ = 0;  // m, the tube's widening last logged
  std::vector<Vec3> route_;     // global route in use as the cold-start guess
  Utime route_utime_ = INT64_MIN;
  bool route_changed_ = false;
  // What the global planner said last, and the points of its route (any
  // kind): the dead-end recovery escapes along them.
  RouteKind route_kind_ = RouteKind::kNone;
  Utime route_kind_utime_ = INT64_MIN;
  std::vector<Vec3> recovery_route_;
  bool last_step_moving_ = false;  // the last step committed a plan that moves off
  LastPlan last_trajectory_kind_ = LastPlan::kMoving;  // what last_trajectory_ is
  BsplineTrajectory last_trajectory_;                  // last published, for the next start
  Utime last_trajectory_t0_ = 0;
  bool stopping_at_target_ = false;  // the last plan stops at the last waypoint
  bool stalled_ = false;             // the last step's warm plan was a stall (logged once)
  int64_t steps_ = 0;
  int64_t ticks_since_nominal_ = 0;
};

}  // namespace ofn::rh
