#pragma once
// Nominal waypoint guidance (the baseline planner of paper Fig. 1): straight
// legs between waypoints flown at cruise speed, speeding up and slowing down
// within a fraction of the acceleration limit, switching to the next leg
// inside the waypoint's capture radius and stopping at the last waypoint.
// With a planner, the leg flown is the planner's (follow_leg): guidance
// flies only what the planner has checked, and where legs lie over each
// other (a route flown out and back) the vehicle's position alone cannot
// say which is meant. A leg taken up from a vehicle off it is rejoined
// along the straight segment the RH optimiser checks before guidance may
// fly (kGuidanceRejoinDistance): the reference never jumps onto the leg.
// Pure core: positions in world NED, SI units.

#include <limits>
#include <optional>
#include <vector>

#include "ofn/common/frames.hpp"
#include "ofn/common/mission_types.hpp"

namespace ofn::control {

struct GuidanceConfig {
  double accel_fraction = 0.8;    // of limits.max_accel used by the reference
  double speed_fraction = 0.995;  // of limits.max_speed the cruise may reach
  double speed_gain = 1.0;        // 1/s, how briskly the reference speed follows its target
  double jerk_fraction = 0.5;     // 1/s: jerk limit as a multiple of limits.max_accel per second
  double max_lead = 8.0;          // m the reference may run ahead of the vehicle along track
  double stop_speed = 0.3;        // m/s, at or below this at the last waypoint counts as arrived
};

struct GuidanceReference {
  Vec3 position = Vec3::Zero();
  Vec3 velocity = Vec3::Zero();
  Vec3 acceleration = Vec3::Zero();
  Vec3 leg_direction = Vec3::UnitX();  // unit vector of the active leg
  int active_waypoint = -1;            // index of the waypoint flown to; -1 without mission
  bool done = false;                   // arrived at the last waypoint
};

class WaypointGuidance {
 public:
  explicit WaypointGuidance(GuidanceConfig config = {}) : config_(config) {}

  /// Starts a plan. The first leg is the one nearest the vehicle, so a
  /// controller restarted mid-flight picks up where the vehicle is; the
  /// reference starts on the vehicle (resync).
  void set_mission(const std::vector<Waypoint>& waypoints, double cruise_speed,
                   const Limits& limits, const Vec3& position, const Vec3& velocity);
  void clear() { waypoints_.clear(); }
  bool has_mission() const { return !waypoints_.empty(); }
  /// Index of the waypoint flown to; -1 without a mission.
  int active_waypoint() const { return waypoints_.empty() ? -1 : active_; }

  /// Puts the reference back on the vehicle, after another source of
  /// reference (a plan, a stop, a hold) has been flown or none was: on the
  /// vehicle's projection when it is on the active leg, otherwise at the
  /// start of a straight rejoin from the vehicle to the leg
  /// kGuidanceRejoinDistance ahead of that projection (or to the leg's end,
  /// if nearer), the path the RH optimiser checked. The speed along is the
  /// vehicle's.
  void resync(const Vec3& position, const Vec3& velocity);

  /// The planner checks and plans along the leg to waypoint `index`:
  /// guidance moves on to it when it is further on, and from now on does
  /// not move past it by its own capture rule (it waits at most the
  /// planner's next step there). `flying`: guidance is the reference flown
  /// now; a move to the next leg then starts where the reference is, as its
  /// own switch does. Otherwise (a plan is flown, or the move skips a
  /// leg) the new leg is the plan's own, from the previous waypoint, and
  /// the reference goes to the vehicle's projection on it. An index of -1
  /// (the planner has no leg) or outside the plan changes nothing.
  /// Returns whether the leg changed.
  bool follow_leg(int index, bool flying, const Vec3& position, const Vec3& velocity);

  /// Advances the reference by dt and returns it. The first update after
  /// set_mission or resync is taken to be at the instant they were given the
  /// vehicle's state, so it does not advance: the reference starts on the
  /// vehicle, not one step ahead of it.
  GuidanceReference update(const Vec3& position, const Vec3& velocity, double dt);

  /// m/s the cruise keeps back from its speed limit (SpeedReserve: room for
  /// gusts); the reference slows towards the lower cruise within its
  /// acceleration and jerk limits. Negative or non-finite counts as zero.
  void set_speed_reserve(double reserve);

 private:
  void start_leg(const Vec3& from, int to_index, double speed_along);
  /// The piece the reference is on becomes the leg being rejoined again.
  void back_on_leg();
  /// From the end of a rejoin on along the leg it met, keeping the part of
  /// the speed that lies along the leg.
  void join_leg();
  /// On to the next leg from where the reference is, keeping the part of
  /// its speed that lies along the new leg.
  void next_leg_from_reference();
  double leg_speed_limit() const;
  bool final_leg() const { return active_ + 1 == static_cast<int>(waypoints_.size()); }

  GuidanceConfig config_;
  std::vector<Waypoint> waypoints_;
  double cruise_speed_ = 0;
  double speed_reserve_ = 0;  // m/s
  Limits limits_;
  int active_ = -1;
  int leg_cap_ = std::numeric_limits<int>::max();  // the planner's leg; no cap without one
  // The straight piece the reference is on: the leg to waypoint active_,
  // or while rejoining it, the rejoin segment.
  Vec3 leg_start_ = Vec3::Zero();
  Vec3 leg_dir_ = Vec3::UnitX();
  double leg_length_ = 0;
  struct Rejoin {
    Vec3 leg_start, leg_dir;
    double leg_length;
    double meets_at;  // m along the leg where the rejoin segment ends
  };
  std::optional<Rejoin> rejoin_;  // the leg being rejoined, while it is
  double s_ = 0, s_dot_ = 0, s_ddot_ = 0;
  bool just_synced_ = false;
  bool done_ = false;
};

}  // namespace ofn::control
