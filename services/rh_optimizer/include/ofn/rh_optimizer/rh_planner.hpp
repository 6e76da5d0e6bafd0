#pragma once
// One receding-horizon step with its warm starts and fallbacks (paper 2.2):
// warm start from the previous solution shifted to now, or from the global
// path when the route changed or the previous solution failed; when a solve
// fails, keep the previous trajectory if it is still safe against the
// current map, otherwise try once more to a nearer terminal x, and failing
// that brake to a hover. Pure core, time in seconds of the
// caller's clock.

#include <limits>
#include <string>
#include <vector>

#include "ofn/rh_optimizer/commit_gate.hpp"
#include "ofn/rh_optimizer/rh_optimizer.hpp"

namespace ofn::rh {

struct FallbackSettings {
  double start_inside_fraction = 0.5;   // a start closer than this share of R_s is not solved from
  double keep_min_remaining = 2.0;      // s a kept trajectory must still run
  double braking_accel_fraction = 0.8;  // of limits.max_accel used to brake
  bool cold_retry = true;               // after a failed warm solve, try once from the path
  bool stall_retry = true;  // a stalled warm plan: also solve from the path, fly the cheaper
  bool short_retry = true;  // before a stop (no plan, none to keep): once more to a nearer x
  /// From a hover, a failed solve from the route: once more from the
  /// straight guess. At rest the next step poses the same problem, so a
  /// solve that fails fails again at every step; SLSQP's failure can turn
  /// on millimetres of the guess (dense seed 142: a 4.3 m escape leg failed
  /// from the route's guess 5 mm off the straight one, which solved).
  bool hover_retry = true;
  double hover_retry_speed = 0.3;     // m/s: a start this slow counts as a hover
  double short_retry_fraction = 0.5;  // of the way from the vehicle to the terminal x
  /// s: while a stop is flown (braking, then its hover) the retries above
  /// (hover_retry, short_retry) run at most this often; the step's own
  /// solve still runs every step. A stop changes the problem slowly, and
  /// each failing solve runs to the time cap: three per step doubled the
  /// lockstep runner's CPU wherever the vehicle brakes (bench1 with unseen
  /// space near the vehicle taken as obstacle, docs/TUNING.md). 0: every
  /// step.
  double braking_retry_period = 0.5;
  double climb_fraction = 0.8;  // of the vertical speed and acceleration limits a climb flies at
  // A climb starts only from a hover this still (the commit gate's start tolerances).
  double climb_start_speed = 0.05;  // m/s
  double climb_start_accel = 0.05;  // m/s^2
};

/// A stall: the vehicle is slow (below kStallSpeedFraction of the speed
/// limit) and so is the plan kStallLookAhead seconds on, yet the plan goes
/// more than kStallMinDisplacement metres. A warm start inherits its
/// predecessor's shape, so a plan that waits before it moves off is re-made
/// from its own first instants at every step and the vehicle never leaves
/// (seen in front of obstacles it had not yet seen round). The look-ahead is
/// long enough for a start from rest under the benchmarks' limits (1.6
/// ft/s^2 through the 0.5 s acceleration lag reaches 1.1 m/s in 3 s, against
/// 0.3 m/s for "slow"); the speed threshold is capped at a quarter of what
/// the acceleration limit reaches in that time for weaker limits. A plan
/// that ends near its start (a stop at the last waypoint a few metres on)
/// is not a stall: from rest it may still be slow 3 s on. Beyond 3 m it is
/// not (at 0.39 m/s^2 through the lag it is past 0.3 m/s by then). With 10
/// m, an escape leg of 8 m went unchecked and its warm plans waited and
/// wiggled for 100 s on random dense field 38.
constexpr double kStallLookAhead = 3.0;        // s
constexpr double kStallSpeedFraction = 0.1;    // of limits.max_speed
constexpr double kStallMinDisplacement = 3.0;  // m
bool plan_stalled(const BsplineTrajectory& trajectory, const RhProblem& problem);

enum class StepMode { kSolved, kKeptPrevious, kBraking };

const char* to_string(StepMode mode);

struct StepInput {
  /// The problem's start (position, velocity, acceleration) is the state the
  /// controller flies now: every committed plan starts on it (CommitGate).
  RhProblem problem;
  double time = 0;                   // s, clock time of the problem's state
  std::vector<Vec3> global_path;     // world NED; empty when there is none
  bool global_path_changed = false;  // a new route since the last step
  SeenQuery seen;                    // cells seen free; empty: the stops skip that rule
};

struct StepOutput {
  StepMode mode = StepMode::kBraking;
  BsplineTrajectory trajectory;  // world NED
  double start_time = 0;         // s, clock time of the trajectory's t = 0
  SolveReport report;            // the last solve of this step (iterations 0 if none ran)
  int solves = 0;                // solves run this step (a cold or stall retry makes 2)
  std::string reason;            // why a fallback was taken, or what the stall retry did
  bool stalled = false;          // the warm plan was a stall (plan_stalled) and was retried
  CommitCheck commit;            // the commit gate's check of the plan flown (or the last refused)
  int refused = 0;               // feasible plans the commit gate refused this step
  std::string refusal;           // why it refused the last of them (another may be flown)
};

/// A climb straight up (or down) from a hover at `from` to a hover at world
/// z `to_z`: a clamped uniform cubic B-spline whose first and last three
/// control points coincide (zero velocity and acceleration at both ends)
/// with the rest evenly spaced between, the number of knot intervals chosen
/// for the shortest duration within `max_speed` and `max_accel` (m/s,
/// m/s^2, both > 0). Empty when the two altitudes are the same.
BsplineTrajectory vertical_move(const Vec3& from, double to_z, double max_speed, double max_accel);

class RhPlanner {
 public:
  explicit RhPlanner(RhSettings settings = {}, FallbackSettings fallback = {},
                     CommitSettings commit = {});

  StepOutput step(const StepInput& input);
  /// One step of a climb straight up to world z `target_z` (dead-end
  /// recovery): planned once, from a hover, by vertical_move at
  /// climb_fraction of the vertical speed and acceleration limits, then
  /// flown while the commit gate accepts it from each step's instant on.
  /// Brakes from a state that is not a hover and when the gate refuses.
  StepOutput climb(const StepInput& input, double target_z);
  /// Forgets the previous solution and any climb (after avoidance hands
  /// back, or a new recovery phase).
  void reset();
  bool has_previous() const { return !previous_.empty(); }

  /// The braking trajectory: from the state now to a hover along the
  /// current velocity at braking_accel_fraction of the limit.
  BsplineTrajectory braking_trajectory(const RhProblem& problem) const;
  /// How far ahead (s) a kept trajectory must be clear of obstacles: the
  /// time to brake from the larger of the current speed and the speed limit,
  /// plus keep_min_remaining.
  double braking_window(const RhProblem& problem) const;

  const RhOptimizer& optimizer() const { return optimizer_; }
  const CommitGate& gate() const { return gate_; }

 private:
  double braking_decel(const RhProblem& problem) const;
  /// `out` (what the step has found so far: solves, refusals, report) as a
  /// stop from the state flown, and the plan left forgotten.
  StepOutput brake(const StepInput& input, StepOutput out, const std::string& why);
  CommitCheck gate_check(const BsplineTrajectory& plan, double elapsed,
                         const StepInput& input) const;

  RhOptimizer optimizer_;
  FallbackSettings fallback_;
  CommitGate gate_;
  // The committed solution the controller flies; empty once a stop is
  // flown, so a fallback never returns to a plan the vehicle has left.
  BsplineTrajectory previous_;
  double previous_start_ = 0;
  BsplineTrajectory climb_;  // the climb flown (empty: none)
  double climb_start_ = 0;   // s, clock time of its t = 0
  // A stop of brake() is flown (no plan of our own since): the retries
  // follow braking_retry_period. Cleared by a solved step and by reset().
  bool braking_ = false;
  double last_braking_retry_ = -std::numeric_limits<double>::infinity();  // s, clock time
};

}  // namespace ofn::rh
