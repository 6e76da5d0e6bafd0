#include "ofn/sim/time_optimal.hpp"

#include <nlopt.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "ofn/common/bspline.hpp"
#include "ofn/global_planner/global_planner.hpp"
#include "ofn/rh_optimizer/rh_optimizer.hpp"
#include "ofn/sim/time_optimal_programme.hpp"
#include "ofn/world/world.hpp"

namespace ofn::baseline {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kTimeScale = Programme::kTimeScale;
constexpr int kMinIntervals = 4;
// Initial routes longer than this times the shortest are not tried.
constexpr double kLongestGuess = 1.5;
// B-spline intervals at most, so that a long course costs accuracy rather
// than unbounded time.
constexpr int kMaxIntervals = 60;
// Gate-to-gate times this close (s) tie; the shorter whole flight wins.
constexpr double kTie = 0.01;

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

std::string format_seconds(double s) {
  std::ostringstream o;
  o.precision(3);
  o << std::fixed << s;
  return o.str();
}

struct SolveContext {
  const Programme* programme = nullptr;
  int evaluations = 0;
};

double objective_callback(unsigned, const double* z, double* grad, void* data) {
  auto* context = static_cast<SolveContext*>(data);
  ++context->evaluations;
  return context->programme->objective(z, grad);
}

void constraint_callback(unsigned, double* result, unsigned, const double* z, double* grad,
                         void* data) {
  static_cast<SolveContext*>(data)->programme->constraints(z, result, grad);
}

/// A polyline from the start, cut (or extended along +x) at the finish plane.
struct Guess {
  std::string name;
  std::vector<Vec3> points;
};

std::vector<Vec3> end_at_finish(std::vector<Vec3> points, double finish_x) {
  for (size_t i = 1; i < points.size(); ++i) {
    if (points[i].x() >= finish_x && points[i - 1].x() < finish_x) {
      const double f = (finish_x - points[i - 1].x()) / (points[i].x() - points[i - 1].x());
      points[i] = points[i - 1] + f * (points[i] - points[i - 1]);
      points.resize(i + 1);
      return points;
    }
  }
  Vec3 last = points.back();
  if (last.x() < finish_x) {
    last.x() = finish_x;
    points.push_back(last);
  }
  return points;
}

double polyline_length(const std::vector<Vec3>& points) {
  double length = 0;
  for (size_t i = 1; i < points.size(); ++i) length += (points[i] - points[i - 1]).norm();
  return length;
}

Vec3 point_at_length(const std::vector<Vec3>& points, double length) {
  for (size_t i = 1; i < points.size(); ++i) {
    const double segment = (points[i] - points[i - 1]).norm();
    if (length <= segment && segment > 0)
      return points[i - 1] + (length / segment) * (points[i] - points[i - 1]);
    length -= segment;
  }
  return points.back();
}

/// Lateral and vertical offset of a polyline at a few stations along x, to
/// tell different routes apart.
std::vector<Vec3> stations(const std::vector<Vec3>& points, const Course& c) {
  std::vector<Vec3> out;
  constexpr int kStations = 24;
  for (int k = 0; k <= kStations; ++k) {
    const double x = c.start_x + (c.finish_x - c.start_x) * k / kStations;
    Vec3 at = points.back();
    for (size_t i = 1; i < points.size(); ++i)
      if (points[i].x() >= x && points[i - 1].x() <= x) {
        const double dx = points[i].x() - points[i - 1].x();
        const double f = dx > 0 ? (x - points[i - 1].x()) / dx : 0.0;
        at = points[i - 1] + f * (points[i] - points[i - 1]);
        break;
      }
    out.push_back(at);
  }
  return out;
}

std::vector<Guess> initial_guesses(const Course& c, const BaselineSettings& settings) {
  std::vector<Guess> guesses;
  const Vec3 goal(c.finish_x, c.start.y(), c.start.z());
  const auto& obstacles = c.world->obstacles();
  if (obstacles.empty()) return {{"straight", {c.start, goal}}};

  planning::GlobalPlannerConfig config;
  const double wide_clearance = std::max(c.limits.clearance * settings.guess_clearance_factor, 0.5);
  config.clearance = wide_clearance;
  config.speed = c.limits.max_speed;
  // The optimiser, not the planner's Eq. 10 check, decides what is flyable.
  config.max_accel = 100.0 * c.limits.max_accel;
  config.ground_altitude = c.ground_altitude;
  config.min_altitude = c.floor + 0.1 * c.clearance_scale;
  double top = altitude_of(c, c.start);
  for (const auto& o : obstacles) top = std::max(top, -o.bounds_min().z() - c.ground_altitude);
  config.max_altitude = std::max(config.min_altitude + 1.0, top + 3.0 * config.clearance);
  config.merge_distance = std::min(3.0, 0.5 * config.clearance);
  config.max_obstacles = 2000;
  planning::PlanRequest request;
  request.start = c.start;
  request.start_velocity = c.start_velocity;
  request.goal = goal + Vec3(config.clearance, 0, 0);
  request.leg_from = c.start;
  std::vector<planning::ObstacleBox> boxes;
  for (const auto& o : obstacles) {
    planning::ObstacleBox b;
    b.id = o.spec().id;
    b.min_corner = o.bounds_min();
    b.max_corner = o.bounds_max();
    boxes.push_back(b);
  }
  const double far = 10.0 * (c.finish_x - c.start.x()) + 1000.0;
  auto plan = [&](const std::string& name, auto&& shape) {
    request.obstacles = boxes;
    for (auto& b : request.obstacles) shape(b);
    // With the wider margin gaps may close; then at R_s itself.
    for (const double clearance : {wide_clearance, std::max(c.limits.clearance, 0.5)}) {
      config.clearance = clearance;
      try {
        planning::GlobalPlanner planner(config);
        const auto result = planner.plan(request);
        if (result.status == planning::PlanStatus::kOk && result.waypoints.size() >= 2) {
          guesses.push_back({name, result.waypoints});
          return;
        }
        if (settings.progress)
          settings.progress("no " + name + " route at " + format_seconds(clearance) +
                            " m clearance: " + planning::to_string(result.status));
      } catch (const std::invalid_argument&) {
        // No guess of this kind; the others remain.
      }
    }
  };
  plan("shortest", [](planning::ObstacleBox&) {});
  // Obstacles without a top: the best way round them.
  plan("around", [&](planning::ObstacleBox& b) { b.min_corner.z() = -far; });
  // Obstacles without sides: the best way over them.
  plan("over", [&](planning::ObstacleBox& b) {
    b.min_corner.y() = -far;
    b.max_corner.y() = far;
  });
  // The planner's shortest route is the straight line when nothing is in
  // the way; without any route from it, the straight line is all there is.
  if (guesses.empty()) guesses.push_back({"straight", {c.start, goal}});
  return guesses;
}

/// over / left / right of each obstacle in the way of the straight course
/// line, in order along the course; straight when none is.
std::string classify_route(const Course& c, const std::vector<TrajectorySample>& trajectory) {
  const Vec3 a(c.start_x, c.start.y(), c.start.z()), b(c.finish_x, c.start.y(), c.start.z());
  struct Passage {
    double x;
    std::string word;
  };
  std::vector<Passage> passages;
  for (const auto& o : c.world->obstacles()) {
    // In the way: the straight line at the start's altitude would come
    // within R_s of it.
    bool in_way = false;
    constexpr int kChecks = 400;
    for (int k = 0; k <= kChecks && !in_way; ++k)
      in_way = o.distance(a + (b - a) * k / kChecks) < c.limits.clearance;
    if (!in_way) continue;
    const TrajectorySample* closest = nullptr;
    double best = kInf;
    for (const auto& s : trajectory) {
      const double d = o.distance(s.position);
      if (d < best) {
        best = d;
        closest = &s;
      }
    }
    if (!closest) continue;
    std::string word;
    if (closest->position.z() < o.bounds_min().z())
      word = "over";
    else
      word = closest->position.y() < o.spec().east ? "left" : "right";
    passages.push_back({closest->position.x(), word});
  }
  if (passages.empty()) return "straight";
  std::stable_sort(passages.begin(), passages.end(),
                   [](const Passage& l, const Passage& r) { return l.x < r.x; });
  std::string route;
  for (const auto& p : passages) {
    if (!route.empty() && route.size() >= p.word.size() &&
        route.compare(route.size() - p.word.size(), p.word.size(), p.word) == 0)
      continue;
    route += (route.empty() ? "" : "-") + p.word;
  }
  return route;
}

/// First time in [lo, hi] where x(t) reaches x_plane (x(lo) below, x(hi) at or above).
double crossing_time(const BsplineTrajectory& traj, double x_plane, double lo, double hi) {
  for (int it = 0; it < 60 && hi - lo > 1e-9; ++it) {
    const double mid = 0.5 * (lo + hi);
    (traj.position(mid).x() >= x_plane ? hi : lo) = mid;
  }
  return hi;
}

/// The final check of a solved trajectory on a fine sampling, and the
/// quantities reported.
struct Verified {
  double worst = kInf;
  int worst_row = 0;
  double start_gate_time = 0, finish_gate_time = 0;
  double min_clearance = kInf, min_altitude = kInf;
  double max_speed = 0, max_accel = 0, max_vertical_speed = 0, min_forward_speed = kInf;
  bool crosses = false;
};

Verified verify(const Course& c, const BsplineTrajectory& traj, double spacing) {
  Verified v;
  const double duration = traj.duration();
  const int n = std::max(2, static_cast<int>(std::ceil(duration / spacing)));
  bool started = false, finished = false;
  double previous_t = 0;
  v.worst = -kInf;
  for (int k = 0; k <= n; ++k) {
    const double t = duration * k / n;
    const Vec3 p = traj.position(t), vel = traj.velocity(t), acc = traj.acceleration(t);
    if (!started && p.x() >= c.start_x) {
      v.start_gate_time = crossing_time(traj, c.start_x, previous_t, t);
      started = true;
    }
    if (!finished && p.x() >= c.finish_x - 1e-9) {
      v.finish_gate_time = crossing_time(traj, c.finish_x - 1e-9, previous_t, t);
      finished = true;
    }
    previous_t = t;
    const auto e = excess(c, p, vel, acc);
    for (int r = 0; r < kRows; ++r)
      if (e[r] > v.worst) {
        v.worst = e[r];
        v.worst_row = r;
      }
    v.min_clearance = std::min(v.min_clearance, c.world->distance_to_obstacles(p));
    v.min_altitude = std::min(v.min_altitude, altitude_of(c, p));
    v.max_speed = std::max(v.max_speed, vel.norm());
    v.max_accel = std::max(v.max_accel, acc.norm());
    v.max_vertical_speed = std::max(v.max_vertical_speed, std::abs(vel.z()));
    v.min_forward_speed = std::min(v.min_forward_speed, vel.x());
  }
  v.crosses = started && finished;
  return v;
}

struct Solved {
  CandidateResult summary;
  BsplineTrajectory trajectory;
  Verified check;
};

Solved solve_guess(const Course& c, const Guess& guess, const BaselineSettings& settings) {
  const auto t0 = std::chrono::steady_clock::now();
  Solved out;
  out.summary.guess = guess.name;
  const std::vector<Vec3> path = end_at_finish(guess.points, c.finish_x);
  const double length = polyline_length(path);
  const double duration = length / (settings.guess_speed_fraction * c.limits.max_speed);
  const int intervals = std::clamp(static_cast<int>(std::ceil(duration / settings.knot_spacing)),
                                   kMinIntervals, kMaxIntervals);
  std::vector<double> z;
  double spacing = settings.sample_spacing;
  // A second, denser pass when the fine check finds the sampled
  // constraints let something slip between the samples.
  for (int pass = 0; pass < 2; ++pass) {
    const double t_guess = z.empty() ? duration : kTimeScale * z[0];
    Programme programme(c, settings.degree, intervals, t_guess, spacing, settings.run_up_weight);
    if (z.empty())
      z = programme.fit([&](double f) { return point_at_length(path, f * length); }, duration);
    SolveContext context;
    context.programme = &programme;
    const int n = programme.num_variables(), m = programme.num_constraints();
    nlopt_opt opt = nlopt_create(NLOPT_LD_SLSQP, static_cast<unsigned>(n));
    std::vector<double> lower(static_cast<size_t>(n), -HUGE_VAL),
        upper(static_cast<size_t>(n), HUGE_VAL);
    lower[0] = 0.5 * (c.finish_x - c.start.x()) / c.limits.max_speed / kTimeScale;
    upper[0] = 20.0 * duration / kTimeScale;
    z[0] = std::clamp(z[0], lower[0], upper[0]);
    nlopt_set_lower_bounds(opt, lower.data());
    nlopt_set_upper_bounds(opt, upper.data());
    nlopt_set_min_objective(opt, objective_callback, &context);
    const std::vector<double> tolerance(static_cast<size_t>(m), 1e-6);
    nlopt_add_inequality_mconstraint(opt, static_cast<unsigned>(m), constraint_callback, &context,
                                     tolerance.data());
    nlopt_set_maxeval(opt, settings.max_evaluations);
    nlopt_set_maxtime(opt, settings.max_solve_time);
    nlopt_set_ftol_rel(opt, 1e-9);
    nlopt_set_xtol_rel(opt, 1e-8);
    double value = 0;
    const nlopt_result status = nlopt_optimize(opt, z.data(), &value);
    nlopt_destroy(opt);
    out.summary.solver_status = rh::nlopt_result_name(status);
    out.summary.evaluations += context.evaluations;
    if (!std::all_of(z.begin(), z.end(), [](double v) { return std::isfinite(v); }) || !(z[0] > 0))
      break;
    out.trajectory = programme.trajectory(z.data());
    out.check = verify(c, out.trajectory, settings.verify_spacing);
    if (out.check.worst <= settings.tolerance) break;
    spacing *= 0.5;
  }
  if (!out.trajectory.empty()) {
    out.summary.worst_violation = std::max(out.check.worst, 0.0);
    out.summary.feasible = out.check.crosses && out.check.worst <= settings.tolerance;
    if (out.check.crosses)
      out.summary.gate_to_gate = out.check.finish_gate_time - out.check.start_gate_time;
  }
  out.summary.solve_time = seconds_since(t0);
  return out;
}

std::vector<TrajectorySample> sample(const BsplineTrajectory& traj, double end, double spacing) {
  std::vector<TrajectorySample> out;
  const int n = std::max(1, static_cast<int>(std::ceil(end / spacing)));
  for (int k = 0; k <= n; ++k) {
    const double t = std::min(k * spacing, end);
    out.push_back({t, traj.position(t), traj.velocity(t), traj.acceleration(t)});
  }
  return out;
}

/// Least length to the finish plane of a path from the start gate plane
/// (anywhere on it) or, from_start, from the start position.
double lattice_bound(const Course& c, const BaselineSettings& settings, bool from_start) {
  const double rs = c.limits.clearance;
  const double first_x = from_start ? c.start.x() : c.start_x;
  const double span = c.finish_x - first_x;
  const double h_wanted =
      settings.bound_slice_spacing > 0 ? settings.bound_slice_spacing : std::max(rs, 0.5);
  const int slices = std::max(1, static_cast<int>(std::ceil(span / h_wanted)));
  const double h = span / slices;
  // Beyond every obstacle by R_s in y and above every top by R_s, a path
  // can be clamped onto the domain's boundary without getting longer or
  // losing clearance, so the domain below holds a shortest path.
  double y_lo = c.start.y(), y_hi = c.start.y();
  double alt_hi = altitude_of(c, c.start);
  for (const auto& o : c.world->obstacles()) {
    y_lo = std::min(y_lo, o.bounds_min().y() - rs);
    y_hi = std::max(y_hi, o.bounds_max().y() + rs);
    alt_hi = std::max(alt_hi, -o.bounds_min().z() - c.ground_altitude + rs);
  }
  const double alt_lo = c.floor;
  const int shift = std::max(1, settings.bound_max_shift);
  // With the cell a shift-th of the slice spacing, a shift beyond the
  // window is priced at 45 degrees at least: never a cheap way round.
  double g = settings.bound_cell > 0 ? settings.bound_cell : std::max(h / shift, 0.05);
  constexpr double kMaxCells = 40000;
  const double area = (y_hi - y_lo + g) * (alt_hi - alt_lo + g);
  if (area / (g * g) > kMaxCells) g = std::sqrt(area / kMaxCells);
  const int ny = std::max(1, static_cast<int>(std::ceil((y_hi - y_lo) / g)));
  const int nz = std::max(1, static_cast<int>(std::ceil((alt_hi - alt_lo) / g)));
  // Least distance between two cells (squares of side g) on consecutive
  // slices, by their index offset.
  std::vector<double> step_cost(static_cast<size_t>((2 * shift + 1) * (2 * shift + 1)));
  for (int dj = -shift; dj <= shift; ++dj)
    for (int dk = -shift; dk <= shift; ++dk) {
      const double gy = std::max(std::abs(dj) - 1, 0) * g, gz = std::max(std::abs(dk) - 1, 0) * g;
      step_cost[static_cast<size_t>((dj + shift) * (2 * shift + 1) + dk + shift)] =
          std::sqrt(h * h + gy * gy + gz * gz);
    }
  // Any larger offset is at least this far.
  const double jump_cost = std::sqrt(h * h + shift * g * shift * g);
  const double half_diagonal = g / std::sqrt(2.0);
  auto free_cells = [&](int slice) {
    std::vector<char> free(static_cast<size_t>(ny * nz));
    const double x = first_x + slice * h;
    for (int j = 0; j < ny; ++j)
      for (int k = 0; k < nz; ++k) {
        const Vec3 centre(x, y_lo + (j + 0.5) * g, -(alt_lo + (k + 0.5) * g) - c.ground_altitude);
        // Distance is 1-Lipschitz: no point of the cell keeps R_s unless
        // its centre keeps R_s less the half diagonal.
        free[static_cast<size_t>(j * nz + k)] =
            c.world->distance_to_obstacles(centre) >= rs - half_diagonal;
      }
    return free;
  };
  std::vector<double> cost(static_cast<size_t>(ny * nz)), next(cost.size());
  {
    const auto free = free_cells(0);
    for (size_t i = 0; i < cost.size(); ++i) cost[i] = free[i] ? 0.0 : kInf;
    if (from_start) {
      const int j = std::clamp(static_cast<int>((c.start.y() - y_lo) / g), 0, ny - 1);
      const int k = std::clamp(static_cast<int>((altitude_of(c, c.start) - alt_lo) / g), 0, nz - 1);
      const size_t start_cell = static_cast<size_t>(j * nz + k);
      std::fill(cost.begin(), cost.end(), kInf);
      cost[start_cell] = 0.0;
    }
  }
  for (int slice = 1; slice <= slices; ++slice) {
    const auto free = free_cells(slice);
    const double best_previous = *std::min_element(cost.begin(), cost.end());
    for (int j = 0; j < ny; ++j)
      for (int k = 0; k < nz; ++k) {
        const size_t here = static_cast<size_t>(j * nz + k);
        if (!free[here]) {
          next[here] = kInf;
          continue;
        }
        double best = best_previous + jump_cost;
        for (int dj = std::max(-shift, -j); dj <= std::min(shift, ny - 1 - j); ++dj)
          for (int dk = std::max(-shift, -k); dk <= std::min(shift, nz - 1 - k); ++dk) {
            const double from = cost[static_cast<size_t>((j + dj) * nz + k + dk)];
            if (from == kInf) continue;
            best = std::min(
                best,
                from + step_cost[static_cast<size_t>((dj + shift) * (2 * shift + 1) + dk + shift)]);
          }
        next[here] = best;
      }
    std::swap(cost, next);
  }
  return std::max(span, *std::min_element(cost.begin(), cost.end()));
}

}  // namespace

double path_length_lower_bound(const Scenario& scenario, const BaselineSettings& settings) {
  const world::World world(scenario.obstacles, scenario.ground_altitude);
  const Course course = make_course(scenario, world, settings);
  return lattice_bound(course, settings, false);
}

BaselineResult compute_time_optimal(const Scenario& scenario, const BaselineSettings& settings) {
  const auto t0 = std::chrono::steady_clock::now();
  // Every obstacle the course ever has counts, whenever it appears.
  const world::World world(scenario.obstacles, scenario.ground_altitude);
  const Course course = make_course(scenario, world, settings);
  auto say = [&](const std::string& line) {
    if (settings.progress) settings.progress(line);
  };

  BaselineResult result;
  result.path_length_lower_bound = lattice_bound(course, settings, false);
  result.lower_bound = result.path_length_lower_bound / course.limits.max_speed;
  result.total_path_length_lower_bound = lattice_bound(course, settings, true);
  result.total_time_lower_bound = result.total_path_length_lower_bound / course.limits.max_speed;
  say(scenario.name + ": lower bounds " + format_seconds(result.lower_bound) + " s gate to gate, " +
      format_seconds(result.total_time_lower_bound) + " s from the start (" +
      format_seconds(seconds_since(t0)) + " s)");

  std::vector<Guess> guesses = initial_guesses(course, settings);
  // A route much longer than the shortest guess cannot win, and its long
  // programme would cost most of the time.
  double shortest_guess = kInf;
  for (const Guess& g : guesses)
    shortest_guess =
        std::min(shortest_guess, polyline_length(end_at_finish(g.points, course.finish_x)));
  std::vector<std::vector<Vec3>> seen;
  const double same_route = 0.5 * course.clearance_scale;
  Solved best;
  for (const Guess& guess : guesses) {
    if (best.summary.feasible && seconds_since(t0) > settings.max_total_time) {
      say(scenario.name + ": guess " + guess.name + " skipped (time budget spent)");
      continue;
    }
    const std::vector<Vec3> path = end_at_finish(guess.points, course.finish_x);
    if (polyline_length(path) > kLongestGuess * shortest_guess) {
      say(scenario.name + ": guess " + guess.name + " skipped (over " +
          format_seconds(kLongestGuess) + " times the shortest guess's length)");
      continue;
    }
    const auto at = stations(path, course);
    const bool duplicate = std::any_of(seen.begin(), seen.end(), [&](const auto& other) {
      for (size_t k = 0; k < at.size(); ++k)
        if ((at[k] - other[k]).norm() > same_route) return false;
      return true;
    });
    if (duplicate) continue;
    seen.push_back(at);
    Solved solved = solve_guess(course, guess, settings);
    if (!solved.trajectory.empty())
      solved.summary.route =
          classify_route(course, sample(solved.trajectory, solved.trajectory.duration(), 0.5));
    say(scenario.name + ": guess " + guess.name + " -> " +
        (solved.summary.feasible
             ? format_seconds(solved.summary.gate_to_gate) + " s (" + solved.summary.route + ")"
             : "infeasible (worst violation " + format_seconds(solved.summary.worst_violation) +
                   ")") +
        " in " + format_seconds(solved.summary.solve_time) + " s, " +
        std::to_string(solved.summary.evaluations) + " evaluations, " +
        solved.summary.solver_status);
    result.candidates.push_back(solved.summary);
    const bool better =
        solved.summary.feasible &&
        (!best.summary.feasible || solved.summary.gate_to_gate < best.summary.gate_to_gate - kTie ||
         (solved.summary.gate_to_gate < best.summary.gate_to_gate + kTie &&
          solved.check.finish_gate_time < best.check.finish_gate_time));
    if (better || (!best.summary.feasible && !solved.trajectory.empty() &&
                   solved.summary.worst_violation < best.summary.worst_violation))
      best = std::move(solved);
  }

  result.solve_time = seconds_since(t0);
  if (best.trajectory.empty()) {
    result.reason = "no initial guess gave a trajectory";
    return result;
  }
  const Verified& v = best.check;
  result.feasible = best.summary.feasible;
  result.guess = best.summary.guess;
  result.route = best.summary.route;
  result.worst_violation = std::max(v.worst, 0.0);
  result.worst_constraint = kRowNames[v.worst_row];
  result.start_gate_time = v.start_gate_time;
  result.finish_gate_time = v.finish_gate_time;
  result.gate_to_gate = best.summary.gate_to_gate;
  result.min_clearance = v.min_clearance;
  result.min_altitude = v.min_altitude;
  result.max_speed = v.max_speed;
  result.max_accel = v.max_accel;
  result.max_vertical_speed = v.max_vertical_speed;
  result.min_forward_speed = v.min_forward_speed;
  const double end = v.crosses ? v.finish_gate_time : best.trajectory.duration();
  result.trajectory = sample(best.trajectory, end, settings.output_spacing);
  if (!result.feasible) {
    std::ostringstream why;
    why << "no initial guess reached a trajectory within the limits; the least violating ("
        << best.summary.guess << ") exceeds " << result.worst_constraint << " by "
        << 100.0 * result.worst_violation << " %";
    if (!v.crosses) why << " and does not cross both gates";
    result.reason = why.str();
  }
  return result;
}

}  // namespace ofn::baseline
