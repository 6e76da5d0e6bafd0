#include "ofn/rh_optimizer/rh_optimizer.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include <nlopt.h>

#include "ofn/rh_optimizer/rh_nlp.hpp"

namespace ofn::rh {
namespace {

constexpr int kGuessSamples = 40;
// Points of the resampling that names the worst rule of a failed solve.
constexpr int kReportSamples = 100;
// NLopt's SLSQP stops on a small relative cost change even while the
// constraints are still violated by a few thousandths; tight tolerances let
// the iteration and time limits end a solve instead, and a warm start still
// converges in about ten evaluations.
constexpr double kRelativeCostTolerance = 1e-8;
constexpr double kRelativeStepTolerance = 1e-7;

// Share of the acceleration limit the path guess speeds up and slows down
// with: well inside it, so that the commanded acceleration (a + tau da/dt)
// of the fitted spline stays inside too.
constexpr double kGuessAccelFraction = 0.5;

/// Distance along a path against time: from v0 up to `speed` at `accel`,
/// on at `speed`, and down to rest at the end when `stop`; a path too short
/// for that peaks lower. A path started at `speed` with no stop is flown at
/// constant speed, as before there was a profile.
class SpeedProfile {
 public:
  SpeedProfile(double v0, double speed, double accel, double length, bool stop)
      : v0_(v0), accel_(std::max(accel, 1e-6)), length_(length), stop_(stop) {
    peak_ = speed;
    const double up = (peak_ * peak_ - v0_ * v0_) / (2 * accel_);
    const double down = stop_ ? peak_ * peak_ / (2 * accel_) : 0.0;
    if (up + down > length_)
      peak_ = stop_ ? std::sqrt((2 * accel_ * length_ + v0_ * v0_) / 2)
                    : std::sqrt(v0_ * v0_ + 2 * accel_ * length_);
    peak_ = std::max(peak_, v0_);
    t_up_ = (peak_ - v0_) / accel_;
    s_up_ = 0.5 * (v0_ + peak_) * t_up_;
    t_down_ = stop_ ? peak_ / accel_ : 0.0;
    const double s_down = 0.5 * peak_ * t_down_;
    t_cruise_ = std::max(0.0, length_ - s_up_ - s_down) / std::max(peak_, 1e-6);
  }
  double duration() const { return t_up_ + t_cruise_ + t_down_; }
  double distance(double t) const {
    if (t <= t_up_) return std::min(length_, v0_ * t + 0.5 * accel_ * t * t);
    t -= t_up_;
    if (t <= t_cruise_) return std::min(length_, s_up_ + peak_ * t);
    t = std::min(t - t_cruise_, t_down_);
    return std::min(length_, s_up_ + peak_ * t_cruise_ + peak_ * t - 0.5 * accel_ * t * t);
  }

 private:
  double v0_, accel_, length_;
  bool stop_;
  double peak_ = 0, t_up_ = 0, s_up_ = 0, t_down_ = 0, t_cruise_ = 0;
};

bool finite(const Vec3& v) {
  return v.allFinite();
}

// What the NLopt callbacks share: the programme, the evaluation count and
// the best points seen. SLSQP may end on a worse point than one it passed
// (a failed line search, the time limit), so the solve keeps the cheapest
// feasible point and, failing that, the least violating one.
struct SolveContext {
  RhNlp* nlp = nullptr;
  double tolerance = 0;
  int evaluations = 0;
  bool have_feasible = false;
  double best_cost = std::numeric_limits<double>::infinity();
  Eigen::VectorXd best_feasible;
  double least_violation = std::numeric_limits<double>::infinity();
  Eigen::VectorXd least_violating;
  Eigen::VectorXd equality_values;  // scratch for the split equalities
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> equality_jacobian;
  // Screening: the inequality rows the optimiser sees (empty: all of them),
  // and scratch for the full rows they are taken from.
  std::vector<int> screened_rows;
  Eigen::VectorXd inequality_values;
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> inequality_jacobian;

  void consider(const double* z, double scaled_cost) {
    if (!std::isfinite(scaled_cost)) return;
    const double violation = nlp->max_violation(z);
    if (!std::isfinite(violation)) return;
    const int n = nlp->num_variables();
    if (violation <= tolerance && scaled_cost < best_cost) {
      have_feasible = true;
      best_cost = scaled_cost;
      std::copy(z, z + n, best_feasible.data());
    }
    if (violation < least_violation) {
      least_violation = violation;
      std::copy(z, z + n, least_violating.data());
    }
  }
};

double objective_callback(unsigned, const double* z, double* gradient, void* data) {
  auto* context = static_cast<SolveContext*>(data);
  ++context->evaluations;
  const double value = context->nlp->objective(z, gradient);
  context->consider(z, value);
  return value;
}

void inequality_callback(unsigned, double* values, unsigned n, const double* z, double* gradient,
                         void* data) {
  auto* context = static_cast<SolveContext*>(data);
  if (context->screened_rows.empty()) {
    context->nlp->inequalities(z, values, gradient);
    return;
  }
  context->nlp->inequalities(z, context->inequality_values.data(),
                             gradient ? context->inequality_jacobian.data() : nullptr);
  for (size_t i = 0; i < context->screened_rows.size(); ++i) {
    const int row = context->screened_rows[i];
    values[i] = context->inequality_values(row);
    if (gradient) std::copy_n(context->inequality_jacobian.row(row).data(), n, gradient + i * n);
  }
}

void equality_callback(unsigned, double* values, unsigned, const double* z, double* gradient,
                       void* data) {
  static_cast<SolveContext*>(data)->nlp->equalities(z, values, gradient);
}

// For algorithms without equality constraints: |h| <= tolerance / 2 as two
// inequalities.
void split_equality_callback(unsigned, double* values, unsigned n, const double* z,
                             double* gradient, void* data) {
  auto* context = static_cast<SolveContext*>(data);
  const int m = static_cast<int>(context->equality_values.size());
  context->nlp->equalities(z, context->equality_values.data(),
                           gradient ? context->equality_jacobian.data() : nullptr);
  const double band = 0.5 * context->tolerance;
  for (int r = 0; r < m; ++r) {
    values[2 * r] = context->equality_values(r) - band;
    values[2 * r + 1] = -context->equality_values(r) - band;
    if (!gradient) continue;
    for (unsigned j = 0; j < n; ++j) {
      gradient[(2 * r) * n + j] = context->equality_jacobian(r, j);
      gradient[(2 * r + 1) * n + j] = -context->equality_jacobian(r, j);
    }
  }
}

std::string problem_error(const RhProblem& problem) {
  if (!finite(problem.position) || !finite(problem.velocity) || !finite(problem.acceleration))
    return "non-finite start state";
  if (!finite(problem.target) || !std::isfinite(problem.terminal_x))
    return "non-finite target or terminal x";
  if (!problem.frame.origin.allFinite() || !problem.frame.world_from_guidance.allFinite())
    return "non-finite guidance frame";
  const Limits& l = problem.limits;
  if (!(l.max_speed > 0) || !(l.max_accel > 0) || !(l.max_vertical_speed > 0) ||
      !std::isfinite(l.max_speed) || !std::isfinite(l.max_accel) ||
      !std::isfinite(l.max_vertical_speed))
    return "speed and acceleration limits must be positive and finite";
  if (!std::isfinite(l.min_forward_speed) || !(l.clearance >= 0) || !std::isfinite(l.clearance))
    return "non-finite forward speed or clearance limit";
  return {};
}

// Extends a point list straight on at `velocity` for `duration` seconds.
void sample_guess(const BsplineTrajectory* trajectory, double from, double until,
                  const Vec3& end_position, const Vec3& extension_velocity, double extension_time,
                  InitialGuess& guess) {
  const double kept = trajectory ? std::max(until - from, 0.0) : 0.0;
  guess.duration = kept + extension_time;
  guess.positions.resize(kGuessSamples);
  for (int k = 0; k < kGuessSamples; ++k) {
    const double t = guess.duration * k / (kGuessSamples - 1);
    guess.positions[static_cast<size_t>(k)] =
        t < kept ? trajectory->position(from + t)
                 : Vec3(end_position + extension_velocity * (t - kept));
  }
}

/// Guess along a polyline route (world NED, from the vehicle) under a
/// SpeedProfile: from the vehicle's speed along the first step up to
/// `speed`, down to rest at the end when the plan stops at its target.
/// Empty when the route has no length.
InitialGuess guess_along(const std::vector<Vec3>& route, const RhProblem& problem, double speed) {
  std::vector<double> cumulative{0.0};
  for (size_t i = 1; i < route.size(); ++i)
    cumulative.push_back(cumulative.back() + (route[i] - route[i - 1]).norm());
  const double length = cumulative.back();
  if (length < 1e-3) return {};

  // Along the route at `speed`; from a slower vehicle (a hover before an
  // escape) it speeds up first, and a plan that stops at its target slows
  // down at the end: a constant pace would ask for a step in velocity there,
  // which SLSQP may not smooth out within the acceleration limits.
  // It starts at the vehicle's speed along the route's first step: a route
  // that turns away from the velocity starts slower.
  const Vec3 first = route.size() > 1 ? (route[1] - route[0]).normalized() : Vec3::UnitX();
  const SpeedProfile profile(std::clamp(problem.velocity.dot(first), 0.0, speed), speed,
                             kGuessAccelFraction * problem.limits.max_accel, length,
                             problem.stop_at_target);
  InitialGuess guess;
  guess.duration = profile.duration();
  guess.positions.resize(kGuessSamples);
  size_t segment = 0;
  for (int k = 0; k < kGuessSamples; ++k) {
    const double at = profile.distance(guess.duration * k / (kGuessSamples - 1));
    while (segment + 2 < route.size() && cumulative[segment + 1] < at) ++segment;
    const double span = cumulative[segment + 1] - cumulative[segment];
    const double w = span > 0 ? std::clamp((at - cumulative[segment]) / span, 0.0, 1.0) : 0.0;
    guess.positions[static_cast<size_t>(k)] =
        route[segment] + w * (route[segment + 1] - route[segment]);
  }
  return guess;
}

}  // namespace

const char* nlopt_result_name(int result) {
  switch (static_cast<nlopt_result>(result)) {
    case NLOPT_SUCCESS:
      return "success";
    case NLOPT_STOPVAL_REACHED:
      return "stopval reached";
    case NLOPT_FTOL_REACHED:
      return "ftol reached";
    case NLOPT_XTOL_REACHED:
      return "xtol reached";
    case NLOPT_MAXEVAL_REACHED:
      return "evaluation limit";
    case NLOPT_MAXTIME_REACHED:
      return "time limit";
    case NLOPT_FAILURE:
      return "failure";
    case NLOPT_INVALID_ARGS:
      return "invalid arguments";
    case NLOPT_OUT_OF_MEMORY:
      return "out of memory";
    case NLOPT_ROUNDOFF_LIMITED:
      return "roundoff limited";
    case NLOPT_FORCED_STOP:
      return "forced stop";
    default:
      return "unknown result";
  }
}

// ---------------------------------------------------------------------------

double ConstraintReport::worst() const {
  return std::max({clearance, forward_speed, vertical_speed, total_speed, acceleration,
                   commanded_acceleration, altitude, terminal});
}

std::string ConstraintReport::worst_name() const {
  const std::pair<double, const char*> kinds[] = {
      {clearance, "clearance"},
      {forward_speed, "forward_speed"},
      {vertical_speed, "vertical_speed"},
      {total_speed, "total_speed"},
      {acceleration, "acceleration"},
      {commanded_acceleration, "commanded_acceleration"},
      {altitude, "altitude"},
      {terminal, "terminal"}};
  const auto* worst =
      std::max_element(std::begin(kinds), std::end(kinds),
                       [](const auto& a, const auto& b) { return a.first < b.first; });
  return worst->second;
}

// ---------------------------------------------------------------------------

RhOptimizer::RhOptimizer(RhSettings settings)
    : settings_(settings),
      basis_(std::clamp(settings.degree, 1, 7), std::max(settings.intervals, 1)) {
  const RhSettings& s = settings_;
  auto fail = [](const std::string& what) { throw std::invalid_argument("RhSettings: " + what); };
  if (s.degree < 3 || s.degree > 7) fail("degree must be in [3, 7] (jerk enters Eq. 4)");
  if (s.intervals < 1) fail("intervals must be >= 1");
  if (s.collocation_points < 2) fail("collocation_points must be >= 2");
  if (!(s.time_constants.minCoeff() >= 0) || !s.time_constants.allFinite())
    fail("time_constants must be finite and >= 0");
  if (!(s.weights.minCoeff() > 0) || !s.weights.allFinite()) fail("weights must be finite and > 0");
  if (!(s.clearance_margin >= 0) || !std::isfinite(s.clearance_margin))
    fail("clearance_margin must be finite and >= 0");
  if (!std::isfinite(s.min_altitude) || !std::isfinite(s.ground_altitude))
    fail("min_altitude and ground_altitude must be finite");
  if (!(s.min_duration > 0) || !(s.max_duration >= s.min_duration) ||
      !std::isfinite(s.max_duration))
    fail("need 0 < min_duration <= max_duration < inf");
  if (s.max_iterations < 1) fail("max_iterations must be >= 1");
  if (!(s.max_solve_time > 0)) fail("max_solve_time must be > 0");
  if (!(s.feasibility_tolerance > 0) || !std::isfinite(s.feasibility_tolerance))
    fail("feasibility_tolerance must be finite and > 0");
  if (!(s.screening_margin >= 0) || !std::isfinite(s.screening_margin))
    fail("screening_margin must be finite and >= 0");
  if (s.max_screening_rounds < 1) fail("max_screening_rounds must be >= 1");
  nlp_ = std::make_unique<RhNlp>(settings_, basis_);
}

RhOptimizer::~RhOptimizer() = default;
RhOptimizer::RhOptimizer(RhOptimizer&&) noexcept = default;
RhOptimizer& RhOptimizer::operator=(RhOptimizer&&) noexcept = default;

RhOptimizer::RhOptimizer(const RhOptimizer& other)
    : settings_(other.settings_),
      basis_(other.basis_),
      nlp_(std::make_unique<RhNlp>(other.settings_, other.basis_)) {}

RhOptimizer& RhOptimizer::operator=(const RhOptimizer& other) {
  if (this != &other) {
    settings_ = other.settings_;
    basis_ = other.basis_;
    nlp_ = std::make_unique<RhNlp>(settings_, basis_);
  }
  return *this;
}

double RhOptimizer::required_clearance(const RhProblem& problem, double start_clearance,
                                       double t) const {
  return PointConstraintModel(settings_, problem, start_clearance).required_clearance(t);
}

SolveReport RhOptimizer::solve(const RhProblem& problem, const InitialGuess& guess) {
  const auto started = std::chrono::steady_clock::now();
  SolveReport report;
  report.warm_started = guess.warm;
  auto finish = [&](std::string message) {
    report.message = std::move(message);
    report.solve_time =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    return report;
  };

  if (const std::string error = problem_error(problem); !error.empty()) return finish(error);
  if (guess.positions.empty()) return finish("empty initial guess");
  if (!std::isfinite(guess.duration) || !(guess.duration > 0))
    return finish("initial guess duration must be finite and > 0");
  for (const Vec3& p : guess.positions)
    if (!finite(p)) return finish("non-finite initial guess position");

  RhNlp& nlp = *nlp_;
  nlp.set_problem(problem);
  if (std::isnan(nlp.start_clearance())) return finish("clearance at the start is NaN");

  const int n = nlp.num_variables();
  Eigen::VectorXd z = nlp.fit(guess);
  if (!z.allFinite()) return finish("guess fit is not finite");
  const double initial_cost = nlp.cost(z.data());
  if (!std::isfinite(initial_cost)) return finish("cost of the guess is not finite");
  // Scaled so that the objective starts near 1: SLSQP's first quasi-Newton
  // step assumes a unit Hessian.
  nlp.set_cost_scale(std::max(initial_cost, 1e-6));

  SolveContext context;
  context.nlp = &nlp;
  context.tolerance = settings_.feasibility_tolerance;
  context.best_feasible.resize(n);
  context.least_violating = z;
  const int m_ineq = nlp.num_inequalities();
  const int m_eq = nlp.num_equalities();
  context.equality_values.resize(m_eq);
  context.equality_jacobian.resize(m_eq, n);

  const bool slsqp = settings_.algorithm == RhAlgorithm::kSlsqp;
  std::vector<double> lower, upper;
  nlp.bounds(lower, upper);
  for (int j = 0; j < n; ++j) z(j) = std::clamp(z(j), lower[j], upper[j]);
  // NLopt only stops on ftol/xtol at points it counts as feasible, so the
  // constraint tolerances must be positive or equalities never qualify.
  const double tolerance = 0.5 * settings_.feasibility_tolerance;
  const std::vector<double> ineq_tol(static_cast<size_t>(m_ineq + 2 * m_eq), tolerance);

  // Screening: most rows (the clearance far from anything, the speed at a
  // hover) are nowhere near their limits, and the subproblem's cost grows
  // with the rows it carries. The terminal rows (the last ones) always stay.
  // Only from a warm guess: a cold one is far from the solution, and with
  // the acceleration rows left out its first steps run off to points the
  // next round cannot come back from (measured: from the global path, 59 %
  // of the recorded problems stayed feasible at margin 0.5).
  const double margin = settings_.screening_margin;
  const bool screen = margin > 0 && guess.warm;
  std::vector<char> in_subproblem(static_cast<size_t>(m_ineq), screen ? 0 : 1);
  const auto take_rows_near = [&](const Eigen::VectorXd& point) {
    nlp.inequalities(point.data(), context.inequality_values.data(), nullptr);
    int added = 0;
    for (int r = 0; r < m_ineq; ++r) {
      if (in_subproblem[static_cast<size_t>(r)]) continue;
      if (r >= m_ineq - RhNlp::kNumTerminalInequalities ||
          !(context.inequality_values(r) <= -margin)) {
        in_subproblem[static_cast<size_t>(r)] = 1;
        ++added;
      }
    }
    return added;
  };
  if (screen) {
    context.inequality_values.resize(m_ineq);
    context.inequality_jacobian.resize(m_ineq, n);
    take_rows_near(z);
  }

  nlopt_result result = NLOPT_FAILURE;
  const int rounds = screen ? std::max(1, settings_.max_screening_rounds) : 1;
  for (int round = 0; round < rounds; ++round) {
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    const int evaluations_left = settings_.max_iterations - context.evaluations;
    if (round > 0 && (evaluations_left < 1 || elapsed >= settings_.max_solve_time)) break;
    context.screened_rows.clear();
    if (screen)
      for (int r = 0; r < m_ineq; ++r)
        if (in_subproblem[static_cast<size_t>(r)]) context.screened_rows.push_back(r);
    // Every row in: the plain call (no copying).
    if (static_cast<int>(context.screened_rows.size()) == m_ineq) context.screened_rows.clear();
    const int m_sub =
        context.screened_rows.empty() ? m_ineq : static_cast<int>(context.screened_rows.size());

    nlopt_opt opt = nlopt_create(slsqp ? NLOPT_LD_SLSQP : NLOPT_LD_MMA, static_cast<unsigned>(n));
    if (!opt) return finish("NLopt could not create the optimiser");
    nlopt_set_lower_bounds(opt, lower.data());
    nlopt_set_upper_bounds(opt, upper.data());
    nlopt_set_min_objective(opt, objective_callback, &context);
    nlopt_add_inequality_mconstraint(opt, static_cast<unsigned>(m_sub), inequality_callback,
                                     &context, ineq_tol.data());
    if (slsqp)
      nlopt_add_equality_mconstraint(opt, static_cast<unsigned>(m_eq), equality_callback, &context,
                                     ineq_tol.data());
    else
      nlopt_add_inequality_mconstraint(opt, static_cast<unsigned>(2 * m_eq),
                                       split_equality_callback, &context, ineq_tol.data());
    nlopt_set_maxeval(opt, evaluations_left);
    nlopt_set_maxtime(opt, std::max(1e-4, settings_.max_solve_time - elapsed));
    nlopt_set_ftol_rel(opt, kRelativeCostTolerance);
    nlopt_set_xtol_rel(opt, kRelativeStepTolerance);
    double final_value = 0;
    result = nlopt_optimize(opt, z.data(), &final_value);
    nlopt_destroy(opt);
    ++report.rounds;
    report.subproblem_rows = m_sub;
    // Done unless rows left out come near (or are broken) where the solve
    // ended; then they join and the solve goes on from that point.
    if (!screen || context.screened_rows.empty() || take_rows_near(z) == 0) break;
  }
  if (context.evaluations == 0) context.consider(z.data(), nlp.objective(z.data(), nullptr));

  const Eigen::VectorXd& chosen =
      context.have_feasible ? context.best_feasible : context.least_violating;
  report.iterations = context.evaluations;
  report.max_violation = nlp.max_violation(chosen.data());
  report.cost = nlp.cost(chosen.data());
  report.feasible = context.have_feasible;
  std::ostringstream message;
  message << nlopt_result_name(result);
  if (!report.feasible) message << "; no feasible point, least violation " << report.max_violation;
  if (chosen.allFinite() && std::isfinite(report.cost)) {
    BsplineTrajectory trajectory = nlp.trajectory(chosen.data());
    bool trajectory_finite = true;
    for (const Vec3& c : trajectory.control_points()) trajectory_finite &= finite(c);
    if (trajectory_finite) report.trajectory = std::move(trajectory);
  }
  if (report.trajectory.empty()) {
    report.feasible = false;
    message << "; no finite trajectory";
  } else if (!report.feasible) {
    // Which rule the least violating point breaks most: what a user reading
    // the log needs to know (the clearance, the terminal x, a limit).
    message << " (worst: " << check(problem, report.trajectory, kReportSamples).worst_name() << ")";
  }
  return finish(message.str());
}

ConstraintReport RhOptimizer::check(const RhProblem& problem, const BsplineTrajectory& trajectory,
                                    int samples) const {
  constexpr double kUnset = -std::numeric_limits<double>::infinity();
  ConstraintReport report{kUnset, kUnset, kUnset, kUnset, kUnset, kUnset, kUnset, kUnset};
  if (trajectory.empty() || !problem_error(problem).empty()) {
    report = ConstraintReport{};
    report.terminal = std::numeric_limits<double>::infinity();
    return report;
  }
  const double start_clearance = problem.clearance ? problem.clearance(problem.position).distance
                                                   : std::numeric_limits<double>::infinity();
  const PointConstraintModel model(settings_, problem, start_clearance);
  const Mat3 guidance_from_world = problem.frame.world_from_guidance.transpose();
  const double T = trajectory.duration();
  samples = std::max(samples, 1);
  PointConstraintModel::Result result;
  std::array<Vec3, 4> state;
  for (int i = 1; i <= samples; ++i) {
    const double t = T * i / samples;
    for (int k = 0; k < 4; ++k) {
      const Vec3 world = trajectory.evaluate(t, k) - (k == 0 ? problem.position : Vec3::Zero());
      state[k] = guidance_from_world * world;
    }
    model.evaluate(state, t, false, result);
    report.clearance = std::max(report.clearance, result.value[kClearanceRow]);
    report.forward_speed = std::max(report.forward_speed, result.value[kForwardSpeedRow]);
    report.vertical_speed = std::max(
        {report.vertical_speed, result.value[kClimbSpeedRow], result.value[kDescentSpeedRow]});
    report.total_speed = std::max(report.total_speed, result.value[kTotalSpeedRow]);
    report.acceleration = std::max(report.acceleration, result.value[kAccelerationRow]);
    report.commanded_acceleration =
        std::max(report.commanded_acceleration, result.value[kCommandedAccelerationRow]);
    report.altitude = std::max(report.altitude, result.value[kAltitudeRow]);
  }

  const Vec3 end_offset = guidance_from_world * (trajectory.position(T) - problem.frame.origin);
  const Vec3 end_velocity = guidance_from_world * trajectory.velocity(T);
  const Vec3 end_accel = guidance_from_world * trajectory.acceleration(T);
  const Limits& l = problem.limits;
  double terminal = std::max({std::abs(end_offset.x() - problem.terminal_x) / RhNlp::kLengthScale,
                              std::abs(end_velocity.z()) / l.max_vertical_speed,
                              -end_velocity.x() / l.max_speed, end_velocity.x() / l.max_speed - 1.0,
                              std::abs(end_velocity.y()) / l.max_speed - 1.0});
  if (settings_.zero_terminal_accel)
    terminal = std::max(terminal, end_accel.cwiseAbs().maxCoeff() / l.max_accel);
  if (problem.stop_at_target) {
    const Vec3 target_offset = guidance_from_world * (problem.target - problem.frame.origin);
    terminal = std::max(
        {terminal,
         (end_offset - target_offset).tail<2>().cwiseAbs().maxCoeff() / RhNlp::kLengthScale,
         end_velocity.head<2>().cwiseAbs().maxCoeff() / l.max_speed});
  }
  report.terminal = terminal;
  return report;
}

// ---------------------------------------------------------------------------

InitialGuess RhOptimizer::guess_from_previous(const BsplineTrajectory& previous, double elapsed,
                                              const RhProblem& problem) {
  InitialGuess guess;
  guess.warm = true;
  if (previous.empty() || !std::isfinite(elapsed)) return guess;
  const GuidanceFrame& frame = problem.frame;
  const double max_speed = std::max(problem.limits.max_speed, 1e-3);
  const double from = std::clamp(elapsed, 0.0, previous.duration());
  double until = previous.duration();

  // Cut the previous solution where it passes the new terminal x, if it does.
  if (frame.to_guidance(previous.position(until)).x() > problem.terminal_x) {
    constexpr int kScan = 200;
    for (int k = 0; k <= kScan; ++k) {
      const double t = from + (until - from) * k / kScan;
      if (frame.to_guidance(previous.position(t)).x() >= problem.terminal_x) {
        until = std::max(t, from);
        break;
      }
    }
  }
  const Vec3 end_position = previous.position(until);
  Vec3 end_velocity = previous.velocity(until);
  const double remaining_x = problem.terminal_x - frame.to_guidance(end_position).x();
  const Vec3 leg = frame.world_from_guidance.col(0);
  double extension_time = 0;
  if (remaining_x > 1e-6) {
    const double along = end_velocity.dot(leg);
    if (along < 0.1 * max_speed) {
      end_velocity = leg * std::clamp(end_velocity.norm(), 0.5 * max_speed, max_speed);
    }
    extension_time = remaining_x / end_velocity.dot(leg);
  }
  if (until - from + extension_time < 1e-3) {
    end_velocity = leg * 0.5 * max_speed;
    extension_time = 1.0;
  }
  sample_guess(&previous, from, until, end_position, end_velocity, extension_time, guess);
  return guess;
}

InitialGuess RhOptimizer::guess_from_path(const std::vector<Vec3>& path, const RhProblem& problem,
                                          double speed) {
  if (path.empty()) return guess_straight(problem);
  const GuidanceFrame& frame = problem.frame;
  speed = std::clamp(speed, 0.1, std::max(problem.limits.max_speed, 0.1));
  const double start_x = frame.to_guidance(problem.position).x();
  if (start_x >= problem.terminal_x) return guess_straight(problem);

  // The point of the polyline nearest the vehicle.
  size_t nearest_segment = 0;
  Vec3 nearest = path.front();
  double nearest_distance = (path.front() - problem.position).norm();
  for (size_t i = 0; i + 1 < path.size(); ++i) {
    const Vec3 d = path[i + 1] - path[i];
    const double length_sq = d.squaredNorm();
    const double u =
        length_sq > 0 ? std::clamp((problem.position - path[i]).dot(d) / length_sq, 0.0, 1.0) : 0;
    const Vec3 p = path[i] + u * d;
    const double distance = (p - problem.position).norm();
    if (distance < nearest_distance) {
      nearest_distance = distance;
      nearest = p;
      nearest_segment = i;
    }
  }

  std::vector<Vec3> route{problem.position};
  auto append = [&](const Vec3& p) {
    if ((p - route.back()).norm() > 1e-6) route.push_back(p);
  };
  append(nearest);
  bool reached = false;
  for (size_t i = nearest_segment + 1; i < path.size() && !reached; ++i) {
    const Vec3& a = route.back();
    const Vec3& b = path[i];
    const double xa = frame.to_guidance(a).x();
    const double xb = frame.to_guidance(b).x();
    if (xb >= problem.terminal_x) {
      const double w = xb > xa ? std::clamp((problem.terminal_x - xa) / (xb - xa), 0.0, 1.0) : 1.0;
      append(a + w * (b - a));
      reached = true;
    } else {
      append(b);
    }
  }
  if (!reached) {
    const double remaining = problem.terminal_x - frame.to_guidance(route.back()).x();
    if (remaining > 0) append(route.back() + frame.world_from_guidance.col(0) * remaining);
  }

  if (InitialGuess guess = guess_along(route, problem, speed); !guess.positions.empty())
    return guess;
  return guess_straight(problem);
}

InitialGuess RhOptimizer::guess_straight(const RhProblem& problem) {
  const double max_speed = std::max(problem.limits.max_speed, 1e-3);
  const double speed = std::clamp(problem.velocity.norm(), 0.5 * max_speed, max_speed);
  const Vec3 leg = problem.frame.world_from_guidance.col(0);
  const double distance =
      std::max(problem.terminal_x - problem.frame.to_guidance(problem.position).x(), speed * 1.0);
  // Profiled like a route's guess (from the vehicle's speed, to rest on the
  // target when the plan stops there). At constant speed a short plan from
  // a hover asked for a step in velocity: from rest to a stop 1-5 m on, no
  // cold solve found a feasible point.
  const Vec3 end =
      problem.stop_at_target ? problem.target : Vec3(problem.position + leg * distance);
  if (InitialGuess guess = guess_along({problem.position, end}, problem, speed);
      !guess.positions.empty())
    return guess;
  InitialGuess guess;
  sample_guess(nullptr, 0, 0, problem.position, leg * speed, distance / speed, guess);
  return guess;
}

}  // namespace ofn::rh
