#pragma once
// The receding-horizon trajectory optimisation of paper 4.1 (Eqs. 1-8) as a
// nonlinear programme over B-spline flat outputs, solved by SLSQP (NLopt).
//
// Decision variables: the control points of x(t), y(t), z(t) in the guidance
// frame (x along the leg) beyond the first three, which the initial state
// (Eq. 5) fixes by construction, and the free final time T.
// Cost (Eq. 1): integral over [0, T] of the weighted squared distance to the
// target, by Gauss-Legendre quadrature on the spline.
// Terminal (Eq. 6): x(T) = terminal_x; 0 <= u(T) <= u_U; |v(T)| <= v_U;
// w(T) = 0; a(T) = 0 when zero_terminal_accel.
// Path (Eqs. 7-8), at every collocation point after the first: clearance
// from the distance field >= the required clearance; 0 <= u (forward speed
// >= min_forward_speed, plus forward_speed_reserve); |w| <=
// max_vertical_speed (w the world's vertical speed, also on a pitched leg);
// total speed <= max_speed; the acceleration ellipse on a and, by Eq. 4
// (a_c = a + tau * da/dt), on the commanded acceleration; altitude >=
// min_altitude.
// All constraints are normalised (divided by their limit) so one tolerance
// fits all; gradients are analytic.
// Pure core: world NED in and out, SI units, no LCM.

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "ofn/common/bspline.hpp"
#include "ofn/common/frames.hpp"
#include "ofn/common/mission_types.hpp"
#include "ofn/map/distance_field.hpp"

namespace ofn::rh {

/// A short name for an NLopt result code (`nlopt_result`, passed as int so
/// that this header does not pull in nlopt.h), for solve reports.
const char* nlopt_result_name(int result);

/// The NLopt algorithm of a solve. SLSQP is the design's choice; MMA (with
/// each equality as a pair of inequalities) is kept for comparison.
enum class RhAlgorithm { kSlsqp, kMma };

struct RhSettings {
  int degree = 5;               // of the flat-output B-splines
  int intervals = 6;            // knot intervals over [0, T]
  int collocation_points = 36;  // equally spaced in t over (0, T], constraints checked here
  Vec3 time_constants = Vec3(0.5, 0.5, 0.5);  // s, tau_x, tau_y, tau_z of Eq. 4
  Vec3 weights = Vec3(30.0, 10.0, 10.0);      // m, R_x, R_y, R_z of Eq. 1
  /// Cost of each second of the horizon, added to Eq. 1 (0: the paper's
  /// cost alone). Eq. 1 pays for time only through the distance still to
  /// go, and near an obstacle it trades speed for deviation.
  double time_weight = 0.0;
  bool zero_terminal_accel = false;  // Eq. 6: a(T) = 0 instead of free
  /// Shares of the speed and acceleration limits kept in reserve: the
  /// constraints hold only at the collocation points (the acceleration
  /// bulges a few per cent between them) and the vehicle tracks to a few
  /// per cent; the benchmarks allow 2 % over a limit.
  /// (0 here, the plain formulation; the service flies with a reserve.)
  double speed_margin = 0.0;
  double accel_margin = 0.0;
  /// Forward speed (m/s) kept by a plan flying sideways under the forward
  /// speed rule: u >= r h^2 / (h^2 + (1 m/s)^2), h the horizontal speed:
  /// nearly r once faster than 1 m/s, 0 at a hover or climbing in place;
  /// room for the controller's tracking error.
  double forward_speed_reserve = 0.0;
  double clearance_margin = 1.0;        // m planned beyond limits.clearance (tracking error room)
  double min_altitude = 6.0;            // m above ground
  double ground_altitude = 0.0;         // m; the ground is at world z = -ground_altitude
  double min_duration = 2.0;            // s, bounds on the free final time
  double max_duration = 60.0;           // s
  int max_iterations = 60;              // objective evaluations per solve (NLopt maxeval)
  double max_solve_time = 0.05;         // s of wall time per solve
  double feasibility_tolerance = 2e-3;  // worst normalised violation accepted as feasible
  RhAlgorithm algorithm = RhAlgorithm::kSlsqp;
  /// Constraint screening: a path-constraint row further than this below
  /// its limit (normalised, as in ConstraintReport) where the solve starts
  /// is left out of the optimiser's subproblem; rows the result comes this
  /// near (or breaks) are added and the solve goes on from there. Every
  /// point is still judged feasible against every row. 0: all rows always.
  double screening_margin = 0.0;
  int max_screening_rounds = 3;  // solves per call with rows added between them
};

/// Clearance (m, negative inside) and its gradient at a world NED point.
using ClearanceQuery = std::function<mapping::DistanceSample(const Vec3& ned)>;

struct RhProblem {
  GuidanceFrame frame;               // x from the previous waypoint towards the target
  Vec3 position = Vec3::Zero();      // m, world NED, now (Eq. 5)
  Vec3 velocity = Vec3::Zero();      // m/s
  Vec3 acceleration = Vec3::Zero();  // m/s^2
  Vec3 target = Vec3::Zero();        // m, world NED (Eq. 1)
  double terminal_x = 0;             // m, guidance-frame x_f (Eq. 6)
  /// The trajectory ends at rest at `target` (x_f is the target's x): the
  /// last waypoint is within the horizon, and the vehicle stops there.
  bool stop_at_target = false;
  Limits limits;             // SI; limits.max_accel is every ellipse axis
  ClearanceQuery clearance;  // empty: open space
};

/// Where a solve starts: positions (world NED) at equal time steps over
/// [0, duration]; the free control points are fitted to them.
struct InitialGuess {
  std::vector<Vec3> positions;
  double duration = 0;
  bool warm = false;  // from a previous solution (reported in SolveReport)
};

/// Worst normalised violation of each constraint kind (<= 0 means met).
struct ConstraintReport {
  double clearance = 0;  // (required - clearance) / required
  double forward_speed = 0;
  double vertical_speed = 0;
  double total_speed = 0;
  double acceleration = 0;            // ellipse on a
  double commanded_acceleration = 0;  // ellipse on a + tau da/dt
  double altitude = 0;
  double terminal = 0;  // worst of the terminal conditions
  double worst() const;
  std::string worst_name() const;
};

struct SolveReport {
  bool feasible = false;     // every constraint met within feasibility_tolerance
  int iterations = 0;        // SLSQP objective evaluations
  double solve_time = 0;     // s, wall
  double max_violation = 0;  // worst normalised violation at the collocation points
  double cost = 0;           // Eq. 1
  bool warm_started = false;
  int rounds = 0;                // optimiser runs (more than 1 when screened rows joined)
  int subproblem_rows = 0;       // inequality rows the last run carried
  std::string message;           // NLopt's result and anything notable
  BsplineTrajectory trajectory;  // world NED, t from the problem's time
};

class RhNlp;

class RhOptimizer {
 public:
  /// Throws std::invalid_argument on settings out of range.
  explicit RhOptimizer(RhSettings settings = {});
  ~RhOptimizer();
  RhOptimizer(const RhOptimizer& other);
  RhOptimizer& operator=(const RhOptimizer& other);
  RhOptimizer(RhOptimizer&&) noexcept;
  RhOptimizer& operator=(RhOptimizer&&) noexcept;

  /// One solve. Never throws on a bad problem: a non-finite state or an
  /// empty guess gives feasible = false with the reason in message.
  SolveReport solve(const RhProblem& problem, const InitialGuess& guess);

  /// The clearance a trajectory point needs at time t: the planned
  /// clearance, except that a start already inside it may climb back out
  /// at max_speed (so small tracking errors do not make the problem
  /// infeasible).
  double required_clearance(const RhProblem& problem, double start_clearance, double t) const;

  /// Every constraint of the problem checked on `samples` equally spaced
  /// points of a trajectory (fine resampling for verification).
  ConstraintReport check(const RhProblem& problem, const BsplineTrajectory& trajectory,
                         int samples) const;

  /// Warm start: the previous solution from `elapsed` seconds after its
  /// start, extended straight at its end velocity when the new terminal x
  /// lies beyond its end.
  static InitialGuess guess_from_previous(const BsplineTrajectory& previous, double elapsed,
                                          const RhProblem& problem);
  /// Guess along a polyline (the global path, world NED) from its point
  /// nearest the vehicle up to terminal_x, flown at `speed`.
  static InitialGuess guess_from_path(const std::vector<Vec3>& path, const RhProblem& problem,
                                      double speed);
  /// Straight along the leg (to the target when the plan stops there) at
  /// the current speed (at least half the max), speeding up from the
  /// vehicle's speed and slowing to rest as guess_from_path does.
  static InitialGuess guess_straight(const RhProblem& problem);

  const RhSettings& settings() const { return settings_; }

 private:
  RhSettings settings_;
  BsplineBasis basis_;
  std::unique_ptr<RhNlp> nlp_;  // basis tables and scratch, reused across solves
};

}  // namespace ofn::rh
