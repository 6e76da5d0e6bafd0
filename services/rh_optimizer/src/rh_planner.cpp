#include "ofn/rh_optimizer/rh_planner.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <sstream>

namespace ofn::rh {
namespace {

constexpr double kMinHold = 2.0;           // s a braking trajectory holds the hover
constexpr double kKeepCheckStep = 0.1;     // s between clearance samples of a kept trajectory
constexpr double kEndsAtRestSpeed = 0.05;  // m/s: a plan ending slower stops in a hover

bool trajectory_finite(const BsplineTrajectory& trajectory) {
  if (trajectory.empty() || !std::isfinite(trajectory.duration())) return false;
  for (const Vec3& c : trajectory.control_points())
    if (!c.allFinite()) return false;
  return true;
}

}  // namespace

bool plan_stalled(const BsplineTrajectory& trajectory, const RhProblem& problem) {
  if (trajectory.empty() || trajectory.duration() <= kStallLookAhead) return false;
  const double slow = std::min(kStallSpeedFraction * problem.limits.max_speed,
                               0.25 * problem.limits.max_accel * kStallLookAhead);
  const Vec3 start = trajectory.position(0.0);
  return problem.velocity.norm() < slow && trajectory.velocity(kStallLookAhead).norm() < slow &&
         (trajectory.position(trajectory.duration()) - start).norm() > kStallMinDisplacement;
}

const char* to_string(StepMode mode) {
  switch (mode) {
    case StepMode::kSolved:
      return "solved";
    case StepMode::kKeptPrevious:
      return "kept_previous";
    case StepMode::kBraking:
      return "braking";
  }
  return "unknown";
}

namespace {

// The gate brakes as the fallback does and keeps the optimiser's ground
// rule: one setting each, here.
CommitSettings with_planner_rules(CommitSettings commit, const RhSettings& settings,
                                  const FallbackSettings& fallback) {
  commit.braking_accel_fraction = fallback.braking_accel_fraction;
  commit.min_altitude = settings.min_altitude;
  commit.ground_altitude = settings.ground_altitude;
  return commit;
}

}  // namespace

RhPlanner::RhPlanner(RhSettings settings, FallbackSettings fallback, CommitSettings commit)
    : optimizer_(settings),
      fallback_(fallback),
      gate_(with_planner_rules(commit, settings, fallback)) {}

CommitCheck RhPlanner::gate_check(const BsplineTrajectory& plan, double elapsed,
                                  const StepInput& input) const {
  const RhProblem& p = input.problem;
  return gate_.check(plan, elapsed, FlownState{p.position, p.velocity, p.acceleration}, p.limits,
                     SafetyMap{p.clearance, input.seen});
}

void RhPlanner::reset() {
  previous_ = BsplineTrajectory();
  previous_start_ = 0;
  climb_ = BsplineTrajectory();
  climb_start_ = 0;
  braking_ = false;
  last_braking_retry_ = -std::numeric_limits<double>::infinity();
}

BsplineTrajectory vertical_move(const Vec3& from, double to_z, double max_speed, double max_accel) {
  const double rise = to_z - from.z();
  if (!(std::abs(rise) > 1e-9) || !(max_speed > 0) || !(max_accel > 0) || !from.allFinite() ||
      !std::isfinite(to_z))
    return {};
  const Vec3 to(from.x(), from.y(), to_z);
  BsplineTrajectory best;
  // Few intervals: a smooth step limited by the acceleration; many: a
  // cruise at the speed limit between short ramps. The duration scales the
  // peaks (speed as 1/T, acceleration as 1/T^2), so each shape is measured
  // once at T = 1 and stretched to the tighter limit.
  for (int intervals = 3; intervals <= 40; ++intervals) {
    std::vector<double> knots(4, 0.0);
    for (int i = 1; i < intervals; ++i) knots.push_back(static_cast<double>(i) / intervals);
    knots.insert(knots.end(), 4, 1.0);
    std::vector<Vec3> control_points;
    const int count = intervals + 3;
    for (int i = 0; i < count; ++i) {
      const double f = std::clamp(static_cast<double>(i - 2) / (count - 5), 0.0, 1.0);
      control_points.push_back(from + (to - from) * f);
    }
    const BsplineTrajectory unit(3, knots, control_points, 1.0);
    double peak_speed = 0, peak_accel = 0;
    constexpr int kSamples = 400;
    for (int k = 0; k <= kSamples; ++k) {
      const double t = static_cast<double>(k) / kSamples;
      peak_speed = std::max(peak_speed, unit.velocity(t).norm());
      peak_accel = std::max(peak_accel, unit.acceleration(t).norm());
    }
    const double duration =
        std::max(peak_speed / max_speed, std::sqrt(peak_accel / max_accel)) * 1.0001;
    if (best.empty() || duration < best.duration())
      best = BsplineTrajectory(3, std::move(knots), std::move(control_points), duration);
  }
  return best;
}

StepOutput RhPlanner::brake(const StepInput& input, StepOutput out, const std::string& why) {
  // The stop from the state flown now; the plan it leaves is forgotten,
  // so no later fallback returns to where the vehicle no longer is.
  out.mode = StepMode::kBraking;
  out.trajectory = braking_trajectory(input.problem);
  out.start_time = std::isfinite(input.time) ? input.time : 0.0;
  out.reason = why;
  const double last_retry = last_braking_retry_;
  reset();
  braking_ = true;
  last_braking_retry_ = last_retry;
  return out;
}

StepOutput RhPlanner::climb(const StepInput& input, double target_z) {
  StepOutput out;
  const RhProblem& problem = input.problem;
  auto brake = [&](const std::string& why) { return this->brake(input, out, why); };
  if (!problem.position.allFinite() || !problem.velocity.allFinite() ||
      !problem.acceleration.allFinite() || !std::isfinite(input.time) || !std::isfinite(target_z))
    return brake("non-finite state, time or climb altitude");
  const bool same_climb =
      !climb_.empty() && std::abs(climb_.position(climb_.duration()).z() - target_z) < 1e-6;
  if (!same_climb) {
    // From a hover only: the climb starts at rest, and the gate holds it to
    // the state flown.
    const double speed = problem.velocity.norm(), accel = problem.acceleration.norm();
    if (!(speed <= fallback_.climb_start_speed && accel <= fallback_.climb_start_accel)) {
      std::ostringstream why;
      why << "not a hover yet (" << speed << " m/s): braking before the climb";
      return brake(why.str());
    }
    climb_ = vertical_move(problem.position, target_z,
                           fallback_.climb_fraction * problem.limits.max_vertical_speed,
                           fallback_.climb_fraction * problem.limits.max_accel);
    climb_start_ = input.time;
    if (climb_.empty()) return brake("no climb: already at its altitude");
  }
  out.commit = gate_check(climb_, input.time - climb_start_, input);
  if (!out.commit.committed) {
    ++out.refused;
    out.refusal = out.commit.reason;
    return brake("the commit gate refused the climb: " + out.commit.reason);
  }
  out.mode = StepMode::kSolved;
  out.trajectory = climb_;
  out.start_time = climb_start_;
  out.reason = "climbing";
  braking_ = false;
  return out;
}

namespace {

/// Cubic in t: c[0] + c[1] t + c[2] t^2 + c[3] t^3.
using Cubic = std::array<double, 4>;

/// The blossom (polar form) of a cubic: the symmetric multi-affine function
/// whose diagonal is the cubic. A B-spline's control point is the blossom
/// of any of its pieces at the knots the control point spans.
double blossom(const Cubic& c, double u1, double u2, double u3) {
  return c[0] + c[1] * (u1 + u2 + u3) / 3.0 + c[2] * (u1 * u2 + u1 * u3 + u2 * u3) / 3.0 +
         c[3] * u1 * u2 * u3;
}

/// d + v u + a u^2 / 2 + j u^3 / 6 with u = t - t0, expanded in t.
Cubic expanded(double t0, double d, double v, double a, double j) {
  const double k2 = 0.5 * a, k3 = j / 6.0;
  return {d - v * t0 + k2 * t0 * t0 - k3 * t0 * t0 * t0, v - 2 * k2 * t0 + 3 * k3 * t0 * t0,
          k2 - 3 * k3 * t0, k3};
}

/// The distance along a stop as a cubic in t on the phase holding `t`:
/// each phase's acceleration is linear in time.
Cubic stop_piece(const StopProfile& stop, double t) {
  const double p = stop.peak_deceleration;
  const double t1 = stop.onset_time, t2 = t1 + stop.constant_time;
  if (t < t1)
    return expanded(0.0, 0.0, stop.velocity.norm(), stop.start_acceleration,
                    (-p - stop.start_acceleration) / t1);
  if (t < t2) return expanded(t1, stop.distance_at(t1), stop.speed_at(t1), -p, 0.0);
  if (t < stop.stop_time)
    return expanded(t2, stop.distance_at(t2), stop.speed_at(t2), -p, p / stop.ramp_time);
  return {stop.distance(), 0.0, 0.0, 0.0};
}

}  // namespace

BsplineTrajectory RhPlanner::braking_trajectory(const RhProblem& problem) const {
  // The stop of braking.hpp (the one the commit gate checks and the
  // controller flies) as a cubic B-spline, exactly: its pieces (onset,
  // constant deceleration, ease-out, hover) are cubics joined with continuous
  // acceleration, so a knot at each join holds them all.
  const Vec3 position = problem.position.allFinite() ? problem.position : Vec3::Zero();
  const Vec3 velocity = problem.velocity.allFinite() ? problem.velocity : Vec3::Zero();
  const Vec3 acceleration =
      problem.acceleration.allFinite() ? problem.acceleration : Vec3(Vec3::Zero());
  const StopProfile stop = stop_from(position, velocity, acceleration, braking_decel(problem));
  const double hold = std::max(kMinHold, stop.stop_time);
  const double duration = stop.stop_time + hold;
  std::vector<double> knots(4, 0.0);  // s, then normalised
  // An onset or constant part too short to matter gets no knot (the next
  // phase's cubic stands in for it, off by far less than a millimetre).
  if (stop.onset_time > 1e-6 * duration) knots.push_back(stop.onset_time);
  if (stop.constant_time > 1e-6 * duration) knots.push_back(stop.onset_time + stop.constant_time);
  // A hover needs no deceleration piece; any interior knot gives the same
  // constant trajectory.
  knots.push_back(stop.stop_time > 0 ? stop.stop_time : 0.5 * duration);
  knots.insert(knots.end(), 4, duration);
  const Vec3 direction = stop.direction();
  std::vector<Vec3> control_points;
  for (std::size_t i = 0; i + 4 < knots.size(); ++i) {
    // Any piece under the control point's support gives the same blossom;
    // take the first non-empty knot interval's.
    std::size_t j = i;
    while (j < i + 3 && !(knots[j + 1] > knots[j])) ++j;
    const Cubic piece = stop_piece(stop, 0.5 * (knots[j] + knots[j + 1]));
    control_points.push_back(position +
                             direction * blossom(piece, knots[i + 1], knots[i + 2], knots[i + 3]));
  }
  for (double& k : knots) k /= duration;
  return BsplineTrajectory(3, std::move(knots), std::move(control_points), duration);
}

double RhPlanner::braking_decel(const RhProblem& problem) const {
  const double limit = problem.limits.max_accel * fallback_.braking_accel_fraction;
  return std::isfinite(limit) && limit > 1e-6 ? limit : 1.0;
}

double RhPlanner::braking_window(const RhProblem& problem) const {
  // The speed the kept plan may reach: at least the horizontal speed limit,
  // whatever the vehicle flies now. A climb at the vertical limit on top adds
  // under a second of braking on the benchmarks' limits, inside the
  // keep_min_remaining added.
  const double speed = std::max(problem.velocity.norm(), problem.limits.max_speed);
  const double stop_time =
      std::isfinite(speed)
          ? stop_from(Vec3::Zero(), Vec3(speed, 0.0, 0.0), braking_decel(problem)).stop_time
          : 0.0;
  return stop_time + fallback_.keep_min_remaining;
}

namespace {

struct Conflict {
  double time = 0;       // s on the plan
  double clearance = 0;  // m there
};

/// The first point of `plan` over [from, from + span], sampled every
/// kKeepCheckStep, that comes within limits.clearance of an obstacle.
std::optional<Conflict> first_conflict(const BsplineTrajectory& plan, double from, double span,
                                       const RhProblem& problem) {
  const int samples = std::max(2, static_cast<int>(std::ceil(span / kKeepCheckStep)));
  for (int k = 0; k <= samples; ++k) {
    const double t = from + span * k / samples;
    const double clearance = problem.clearance(plan.position(t)).distance;
    if (!(clearance >= problem.limits.clearance)) return Conflict{t, clearance};
  }
  return std::nullopt;
}

}  // namespace

StepOutput RhPlanner::step(const StepInput& input) {
  StepOutput out;
  const RhProblem& problem = input.problem;
  auto brake = [&](const std::string& why) { return this->brake(input, out, why); };

  const bool state_finite = problem.position.allFinite() && problem.velocity.allFinite() &&
                            problem.acceleration.allFinite() && std::isfinite(input.time);
  if (!state_finite) return brake("non-finite state or time");

  if (problem.clearance) {
    const double start_clearance = problem.clearance(problem.position).distance;
    const double inside = fallback_.start_inside_fraction * problem.limits.clearance;
    if (!(start_clearance >= inside)) {
      std::ostringstream why;
      why << "start clearance " << start_clearance << " m below " << inside
          << " m: not solved from inside the safety radius";
      return brake(why.str());
    }
  }

  const double max_speed = problem.limits.max_speed;
  const double cruise = std::max(0.5 * max_speed, std::min(problem.velocity.norm(), max_speed));
  auto cold_guess = [&]() {
    return input.global_path.empty()
               ? RhOptimizer::guess_straight(problem)
               : RhOptimizer::guess_from_path(input.global_path, problem, cruise);
  };
  // A feasible, finite plan that the commit gate accepts.
  auto committable = [&](const SolveReport& report) {
    if (!report.feasible || !trajectory_finite(report.trajectory)) return false;
    out.commit = gate_check(report.trajectory, 0.0, input);
    if (!out.commit.committed) {
      ++out.refused;
      out.refusal = out.commit.reason;
    }
    return out.commit.committed;
  };

  const bool warm = has_previous() && !input.global_path_changed;
  InitialGuess guess =
      warm ? RhOptimizer::guess_from_previous(previous_, input.time - previous_start_, problem)
           : cold_guess();
  if (guess.positions.empty()) guess = cold_guess();
  out.report = optimizer_.solve(problem, guess);
  out.solves = 1;
  bool accepted = committable(out.report);
  if (!accepted && guess.warm && fallback_.cold_retry) {
    // A warm solve that failed, or whose plan has no safe stop: once more
    // from the route.
    out.report = optimizer_.solve(problem, cold_guess());
    ++out.solves;
    accepted = committable(out.report);
  }
  // While a stop is flown, the retries below wait for their period (the
  // step's own solve above runs every step).
  // (1 us short of it counts: steps of 0.1 s add up in floating point; a
  // clock that went back counts as due.)
  const double since_retry = input.time - last_braking_retry_;
  const bool retries_due =
      !braking_ || !(since_retry >= 0 && since_retry < fallback_.braking_retry_period - 1e-6);
  bool retried = false;
  if (!accepted && retries_due && fallback_.hover_retry && !input.global_path.empty() &&
      problem.velocity.norm() < fallback_.hover_retry_speed) {
    // The route's guess failed (warm, then cold, or cold alone) from a
    // hover: once more from the straight one (FallbackSettings::hover_retry).
    SolveReport straight = optimizer_.solve(problem, RhOptimizer::guess_straight(problem));
    ++out.solves;
    retried = true;
    if (committable(straight)) {
      out.report = std::move(straight);
      accepted = true;
    }
  }
  if (accepted && guess.warm && fallback_.stall_retry &&
      plan_stalled(out.report.trajectory, problem)) {
    SolveReport cold = optimizer_.solve(problem, cold_guess());
    ++out.solves;
    out.stalled = true;
    const CommitCheck warm_check = out.commit;
    if (cold.cost < out.report.cost && committable(cold)) {
      out.report = std::move(cold);
      out.reason = "warm plan stalled; the plan from the route is cheaper";
    } else {
      out.commit = warm_check;
      out.reason = "warm plan stalled; the plan from the route is no better";
    }
  }

  if (accepted) {
    out.mode = StepMode::kSolved;
    out.trajectory = out.report.trajectory;
    out.start_time = input.time;
    previous_ = out.report.trajectory;
    previous_start_ = input.time;
    braking_ = false;
    return out;
  }

  std::string failure = "solve failed (" + out.report.message + ")";
  if (out.report.feasible && out.refused > 0) failure = "plan refused (" + out.commit.reason + ")";
  // Once more, to a nearer x. The horizon ends past the farthest obstacle
  // seen, and what lies between may leave no plan that gets there: behind
  // the gap between two tall obstacles, the space they hide (taken as
  // obstacle) and the next obstacle beyond can close the way until the
  // vehicle is through and sees round them. A plan to a nearer x is enough
  // now: the commit gate still demands its stops, and the next steps reach
  // farther. Tried where the alternative is a stop, or a kept plan that
  // is known to run into something later (it only puts off the stop); a
  // previous plan clear to its end is the better of the two.
  auto nearer = [&](const std::string& why) {
    if (!fallback_.short_retry || problem.stop_at_target || !retries_due) return false;
    retried = true;
    RhProblem closer = problem;
    const double x0 = problem.frame.to_guidance(problem.position).x();
    closer.terminal_x = x0 + fallback_.short_retry_fraction * (problem.terminal_x - x0);
    const InitialGuess near_guess =
        input.global_path.empty() ? RhOptimizer::guess_straight(closer)
                                  : RhOptimizer::guess_from_path(input.global_path, closer, cruise);
    SolveReport near = optimizer_.solve(closer, near_guess);
    ++out.solves;
    if (!committable(near)) return false;
    out.report = std::move(near);
    out.mode = StepMode::kSolved;
    out.trajectory = out.report.trajectory;
    out.start_time = input.time;
    out.reason = why + "; flying a plan to a nearer x instead";
    previous_ = out.report.trajectory;
    previous_start_ = input.time;
    braking_ = false;
    return true;
  };
  auto nearer_or_brake = [&](const std::string& why) {
    if (nearer(why)) return out;
    // The period counts from a step whose retries ran and failed.
    if (retried) last_braking_retry_ = input.time;
    return brake(why);
  };
  if (!has_previous()) return nearer_or_brake(failure + "; no previous trajectory");
  const double elapsed = input.time - previous_start_;
  const double remaining = previous_.duration() - elapsed;
  // A kept trajectory must leave time for more solves and for the braking
  // that would follow it, unless it ends at rest (a stop at the last
  // waypoint, whose solves are the hardest): kept to its end, it is itself
  // the braking, and it stops where it should.
  const bool ends_at_rest = previous_.velocity(previous_.duration()).norm() < kEndsAtRestSpeed;
  if (remaining <= 0.0 || (remaining < fallback_.keep_min_remaining && !ends_at_rest)) {
    std::ostringstream why;
    why << failure << "; previous has " << std::max(remaining, 0.0) << " s left, needs "
        << fallback_.keep_min_remaining;
    return nearer_or_brake(why.str());
  }
  if (problem.clearance) {
    // Only the part of the kept plan that braking could no longer avoid has
    // to be clear: a conflict farther ahead is met by the next steps, which
    // check it again, solve again, and brake before it comes this close. A
    // new cuboid grazing the far end of the horizon then costs a replan, not
    // a stop at cruise speed.
    const double checked = std::min(remaining, braking_window(problem));
    if (const auto conflict = first_conflict(previous_, elapsed, checked, problem)) {
      std::ostringstream why;
      why << failure << "; previous comes within " << conflict->clearance << " m of an obstacle at "
          << conflict->time << " s";
      return nearer_or_brake(why.str());
    }
  }
  // The kept plan must still start on the state flown now and carry a safe
  // stop on today's map, as a new one would.
  const CommitCheck kept = gate_check(previous_, elapsed, input);
  if (!kept.committed) {
    out.commit = kept;
    return nearer_or_brake(failure + "; previous refused (" + kept.reason + ")");
  }
  if (problem.clearance && fallback_.short_retry) {
    // Beyond the braking window: is the kept plan clear to its end?
    const double from = elapsed + std::min(remaining, braking_window(problem));
    const double rest = previous_.duration() - from;
    if (const auto conflict =
            rest > 0 ? first_conflict(previous_, from, rest, problem) : std::nullopt) {
      std::ostringstream why;
      why << failure << "; previous comes within " << conflict->clearance << " m of an obstacle at "
          << conflict->time << " s, beyond the braking window";
      if (nearer(why.str())) return out;
    }
  }
  out.commit = kept;
  out.mode = StepMode::kKeptPrevious;
  out.trajectory = previous_;
  out.start_time = previous_start_;
  out.reason = failure + "; keeping the previous trajectory";
  return out;
}

}  // namespace ofn::rh
