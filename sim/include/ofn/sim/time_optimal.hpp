#pragma once
// The offline time-optimal baseline of a course: with full knowledge of the
// obstacles, the least gate-to-gate time any trajectory from the scenario's
// start state can achieve under the flight's limits (speed, total
// acceleration, vertical speed, forward speed, clearance R_s to the real
// obstacle surfaces, an altitude floor). The benchmark report divides each
// flight's gate-to-gate time by it. Also an independent lower bound from the
// shortest clearance-respecting path between the gate planes, as a check.
// Pure core: world NED, SI units, no LCM.

#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "ofn/common/frames.hpp"
#include "ofn/common/scenario.hpp"

namespace ofn::baseline {

struct BaselineSettings {
  // Cost = gate-to-gate time + run_up_weight * time from the start state to
  // the start gate. 1: the fastest whole flight from the start state, timed
  // between the gates. Near 0: the least gate-to-gate time whatever the
  // run-up, which may then take any time to line up beside or above the
  // obstacles before the clock starts (round the far end of a baffle).
  double run_up_weight = 1.0;
  int degree = 5;                       // of the B-spline in x, y, z
  double knot_spacing = 3.0;            // s of the first guess's duration per B-spline interval
  double sample_spacing = 0.25;         // s between the constraint samples of the programme
  double verify_spacing = 0.01;         // s between the samples of the final check
  double output_spacing = 0.1;          // s between the returned trajectory samples
  double guess_speed_fraction = 0.95;   // of max_speed, along the initial polylines
  double guess_clearance_factor = 1.2;  // initial polylines keep this many R_s
  // Largest constraint excess (as a fraction of its limit; clearance and
  // altitude as a fraction of R_s) the final check accepts.
  double tolerance = 0.005;
  double min_altitude = -1;     // m above ground; negative: the smaller of R_s and the start's
  int max_evaluations = 600;    // per initial guess
  double max_solve_time = 8.0;  // s of computation per initial guess and pass
  // Once a feasible trajectory is in hand, no further guess starts after this (s).
  double max_total_time = 20.0;
  // Lower-bound lattice: slices across the course and a grid in each.
  double bound_slice_spacing = 0;  // m; 0: R_s (at least 0.5 m)
  double bound_cell = 0;  // m; 0: slice spacing / bound_max_shift, coarsened for big courses
  // Cells (in y and in z each) within which the lattice prices a shift
  // between slices exactly; any larger shift is priced at this many cells.
  int bound_max_shift = 8;
  // Progress lines for long runs (empty: silent).
  std::function<void(const std::string&)> progress;
};

/// One instant of the trajectory, world NED, t from the start state.
struct TrajectorySample {
  double t = 0;
  Vec3 position = Vec3::Zero();
  Vec3 velocity = Vec3::Zero();
  Vec3 acceleration = Vec3::Zero();
};

/// The outcome of one initial guess.
struct CandidateResult {
  std::string guess;  // which initial polyline
  std::string route;
  bool feasible = false;
  double gate_to_gate = std::numeric_limits<double>::infinity();  // s
  double worst_violation = std::numeric_limits<double>::infinity();
  int evaluations = 0;
  std::string solver_status;  // why SLSQP stopped (last pass)
  double solve_time = 0;      // s of computation
};

struct BaselineResult {
  bool feasible = false;
  std::string reason;  // why not feasible (empty when feasible)
  double gate_to_gate = std::numeric_limits<double>::infinity();  // s
  double start_gate_time = 0;          // s from the start state to the start-gate crossing
  double finish_gate_time = 0;         // s from the start state to the finish-gate crossing
  double lower_bound = 0;              // s, gate to gate; see path_length_lower_bound
  double path_length_lower_bound = 0;  // m between the gate planes
  // The same from the start position to the finish plane: bounds the whole
  // flight's time (finish_gate_time), which run_up_weight 1 minimises.
  double total_time_lower_bound = 0;         // s
  double total_path_length_lower_bound = 0;  // m
  // Final check on the verify_spacing sampling: largest excess over any
  // limit as a fraction of it (clearance and altitude: of R_s); <= 0 when all hold.
  double worst_violation = std::numeric_limits<double>::infinity();
  std::string worst_constraint;  // which limit that was
  double min_clearance = 0;      // m, least true distance to the obstacle surfaces
  double min_altitude = 0;       // m above ground, lowest point
  double max_speed = 0, max_accel = 0, max_vertical_speed = 0;  // over the trajectory
  double min_forward_speed = 0;
  std::string route;  // over, left, right, straight, or a sequence like right-left
  std::string guess;  // the initial guess the result came from
  std::vector<TrajectorySample> trajectory;  // start state to the finish gate
  std::vector<CandidateResult> candidates;   // every guess tried
  double solve_time = 0;                     // s of computation in all
};

/// The baseline of a course. Throws std::invalid_argument when the scenario
/// cannot define one: no timing gates, the start at or beyond the start
/// gate, non-positive limits. An unsolved course comes back with feasible
/// false and the reason.
BaselineResult compute_time_optimal(const Scenario& scenario,
                                    const BaselineSettings& settings = {});

/// Lower bound (m) on the length between the gate planes of every path that
/// keeps R_s to the obstacles and the altitude floor and whose crossings of
/// consecutive lattice slices lie within bound_max_shift cells of each other
/// (see the settings; the docs say in what sense this bounds). Throws like
/// compute_time_optimal.
double path_length_lower_bound(const Scenario& scenario, const BaselineSettings& settings = {});

}  // namespace ofn::baseline
