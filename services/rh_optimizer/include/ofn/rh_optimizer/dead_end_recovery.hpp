#pragma once
// Out of a dead end. The paper's optimiser only ever flies forward along the
// leg (Eq. 8, forward speed >= 0): inside a cul-de-sac, before a wall wider
// than the map or a gap that has closed, no forward plan with a safe stop
// exists, the commit gate lets only stops through and the vehicle hovers for
// ever. This core decides what to do then:
//  1. stuck: avoidance is engaged, and the vehicle hovers with no moving
//     plan committed for `stuck_time`, or, whatever the plans say, it has
//     stayed within `progress_radius` of one spot for `progress_time` (a
//     livelock: each step commits a plan that moves off, the next replaces
//     it before the vehicle has gone anywhere);
//  2. look around: hover and turn the heading through a full turn, so that
//     the scanner (which sees only +-20 deg about the heading) maps what is
//     beside and behind the vehicle, and the global planner re-plans on it;
//  3. then, with the route the global planner finds:
//     - one that heads along the leg from the vehicle: normal planning;
//     - one that turns back (BACKTRACK) or first goes sideways round a
//       wall: escape along it, with the forward speed rule relaxed, leg by
//       straight leg (stopping at each corner, and turning to face each leg
//       before it: the scanner sees only ahead, and the space the leg goes
//       into counts as obstacle until a beam has crossed it), to the first point from
//       which the rest of the route heads along the leg, then normal
//       planning (left to itself, the forward-only optimiser would take the
//       shorter way straight on, back into the dead end);
//     - one through a passage too narrow to fly (the caller's
//       route_flyable says so, and tells the global planner): wait for a
//       newer route;
//     - none: climb straight up by `climb_step`, turning the heading on
//       the way (a climb that turned all round needs no look after it),
//       then look around again, up to `climb_ceiling`. A top no beam went over counts as reaching
//       the ceiling, and the scanner fans only +-42.5 deg about the
//       horizontal: from below, a top far above it is out of the fan near
//       the wall and out of range far from it. From higher up the way over
//       may show;
//     - none at the ceiling: hold the hover and say so (no route), and take
//       up a route if one appears later.
// A climb is safe in the mapped world: obstacles stand on the ground (the
// grid is a height per cell), so the column above a hover clear of every
// obstacle is clear all the way up.
// Every plan flown in recovery passes the same commit gate as any other.
// Pure core: world NED, SI, time in seconds of the caller's clock.

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "ofn/common/frames.hpp"
#include "ofn/rh_optimizer/rh_optimizer.hpp"

namespace ofn::rh {

struct RecoverySettings {
  bool enabled = true;
  double stuck_time = 4.0;       // s hovering without a moving plan before the look-around
  double hover_speed = 0.3;      // m/s below which the vehicle counts as hovering
  double progress_time = 20.0;   // s within progress_radius of one spot: stuck, whatever the plans
  double progress_radius = 3.0;  // m
  double look_turn = 6.2832;     // rad of heading the look-around turns through (a full turn)
  double look_timeout = 40.0;    // s; the look ends then, turned through or not
  double route_wait = 3.0;       // s after the look for the map and the route to take it in
  double route_timeout = 10.0;   // s after the look without a newer route: no route
  double capture_radius = 3.0;   // m from the escape point at which the escape is done
  double face_tolerance =
      0.26;                // rad; an escape leg starts once the heading is this near its direction
  double face_hold = 1.0;  // s facing the leg before it starts (the scanner clears its shadows)
  int max_attempts = 3;  // looks in a row with no escape leg done between: then "no route" for good
  double climb_step = 15.0;      // m climbed after a look that found no route (0: never climb)
  double climb_ceiling = 120.0;  // m above the ground; no climb goes higher
  double climb_tolerance = 0.5;  // m from the climb's altitude at which it is done
  /// s a climb may take beyond climb_step at the vertical speed limit, after
  /// which it ends where it got to (a climb the commit gate refuses stays a
  /// hover).
  double climb_extra_time = 15.0;
  /// A climb goes on past its altitude to the next climb_step without
  /// stopping once its heading has turned all round (the look is done, and
  /// a route made on the way is taken at once, as in any climb):
  /// the caller flies one climb to the ceiling (climb_target()) instead of
  /// a hover, a wait of route_wait and a new climb every climb_step. False:
  /// each climb is flown rest to rest.
  bool climb_through = true;
  /// An escape leg whose way the scanner has already seen (the caller's
  /// way_seen) starts at once, without first turning to face it: after a
  /// look around, the first leg's way has been seen all round. Only from a
  /// hover. False: every leg waits for the turn.
  bool skip_turn_when_seen = false;
};

enum class RecoveryPhase { kIdle, kLooking, kTurning, kEscaping, kClimbing, kNoRoute };
const char* to_string(RecoveryPhase phase);

/// A step's SOLVER_STATS message in `phase`: during an escape it begins
/// "escaping: ", during a climb "climbing: ", whatever the step did
/// (solved, kept, braked, or did not run at all for a blind map). The
/// verdict relaxes the forward-speed rule by this mark and the report
/// counts the time in recovery by it, and the controller flies the escape
/// plan or its stop while the optimiser is blind, so a blind step must not
/// end the span.
std::string recovery_message(RecoveryPhase phase, const std::string& message);

/// What the global planner last said, as the optimiser received it: a
/// route along the leg (also one too sharp to fly at cruise speed), one that
/// turns back, none, or nothing heard yet.
enum class RouteKind { kNone, kForward, kBacktrack, kNoPath };

struct RecoveryInput {
  double time = 0;  // s
  Vec3 position = Vec3::Zero();
  Vec3 velocity = Vec3::Zero();
  double altitude = 0;              // m above the ground
  double max_vertical_speed = 1.0;  // m/s, the mission's limit (bounds a climb's time)
  double yaw = 0;                   // rad, the vehicle's heading
  bool engaged = false;             // avoidance engaged (false: guidance flies the leg)
  bool moving_plan = false;         // the last step committed a solved plan that moves off
  RouteKind route = RouteKind::kNone;
  double route_time = -1e300;  // s, when that route was made
  // world NED, vehicle first: the route's points, whatever its kind
  const std::vector<Vec3>* route_points = nullptr;
  GuidanceFrame leg;  // the mission leg's frame
  /// Asked once per route, when a route is about to be taken (after a
  /// look, on the way up a climb, or after no route):
  /// false when it runs through a passage too narrow to fly that the
  /// global planner has just been told of (find_narrow_passage), so a
  /// newer route is waited for. Empty: every route can be flown.
  std::function<bool()> route_flyable;
  /// Whether every cell of the straight way from `from` to `to` has been
  /// crossed by a beam (VisibilityRecord::seen): an escape along it may
  /// start without turning to face it (skip_turn_when_seen). Empty: never.
  std::function<bool(const Vec3& from, const Vec3& to)> way_seen;
};

struct RecoveryDecision {
  RecoveryPhase phase = RecoveryPhase::kIdle;
  bool changed = false;  // the phase changed on this update
  std::string reason;    // why it changed (empty otherwise)
  // While escaping: where to, from where (the frame's origin, fixed for the
  // escape), and the route points up to there (world NED).
  Vec3 escape_from = Vec3::Zero();
  Vec3 escape_point = Vec3::Zero();
  std::vector<Vec3> escape_route;
  // While looking or turning: the heading turns to the left (anticlockwise
  // seen from above). A look turns to the right; a turn to face the way on
  // takes the shorter way (the one way round cost up to 12 s per escape leg).
  bool turn_left = false;
  // While climbing: the altitude (m above the ground) the climb counts to
  // (its step), and the one to fly to: the step's, or with climb_through
  // the ceiling (the climb then passes each step without stopping).
  double climb_altitude = 0;
  double climb_target = 0;
};

/// Index of the first route point from which every further step heads
/// along the leg, within acos(min_cosine) of its direction (60 deg): where
/// the forward-only optimiser can take over. nullopt for fewer than two
/// points.
std::optional<size_t> forward_from(const std::vector<Vec3>& route, const GuidanceFrame& leg,
                                   double min_cosine = 0.5);

/// Where the next straight leg of an escape along `route` ends: the first
/// corner (the direction turns by more than `corner_angle`, rad) farther
/// than `min_length` from the route's start and before forward_from(), or
/// forward_from() itself. Each leg is flown from rest to rest: a guess
/// along a straight line is one SLSQP can make feasible, a corner taken at
/// speed in the guess is not.
std::optional<size_t> escape_leg_end(const std::vector<Vec3>& route, const GuidanceFrame& leg,
                                     double min_length = 0.0, double corner_angle = 0.26);

class DeadEndRecovery {
 public:
  explicit DeadEndRecovery(RecoverySettings settings = {}) : settings_(settings) {}

  RecoveryDecision update(const RecoveryInput& in);
  /// Back to idle with no attempts counted (a new mission or leg).
  void reset();
  RecoveryPhase phase() const { return decision_.phase; }
  int attempts() const { return attempts_; }
  const RecoverySettings& settings() const { return settings_; }

 private:
  void enter(RecoveryPhase phase, std::string reason);
  enum class Stuck { kNo, kHovering, kNoProgress };
  Stuck stuck(const RecoveryInput& in);
  /// Starts counting the heading turned (a look, or a turn to face the way on).
  void begin_turn(const RecoveryInput& in);
  /// Adds the heading turned since the last update; true after a full turn
  /// or the look's timeout.
  bool turned_through(const RecoveryInput& in);
  /// The heading kTurning turns to, and which way round it is shorter.
  void face(double yaw, const RecoveryInput& in);
  /// Takes up the route of `in` if it leads anywhere: normal planning or
  /// an escape. Returns false when there is none.
  bool take_route(const RecoveryInput& in);
  /// Whether the planner's route (any kind) is newer than `since` and may
  /// be taken: one that runs through a passage too narrow to fly
  /// (route_flyable) is remembered by its stamp and never taken.
  bool route_since(const RecoveryInput& in, double since);
  /// After a look that found no route: a climb if one is left below the
  /// ceiling, else no route. `why` says what the look found.
  void climb_or_hold(const RecoveryInput& in, const std::string& why);

  RecoverySettings settings_;
  RecoveryDecision decision_;
  std::optional<double> stuck_since_;
  // The spot the vehicle has stayed near since `near_since_` (reset when it
  // moves farther than progress_radius from it, and on every phase change).
  std::optional<Vec3> near_spot_;
  double near_since_ = 0;
  double turned_ = 0;  // rad of heading turned since the look began
  double last_yaw_ = 0;
  double look_start_ = 0;
  std::optional<double> look_end_;
  std::optional<double> facing_since_;
  double face_yaw_ = 0;                              // rad, where kTurning turns to
  RecoveryPhase after_turn_ = RecoveryPhase::kIdle;  // what follows kTurning
  int attempts_ = 0;
  double climb_start_ = 0;  // s, when the climb began
  // The stamp of the last route found to run through a narrow passage:
  // only a newer one is taken.
  double narrow_route_time_ = -1e300;
};

}  // namespace ofn::rh
