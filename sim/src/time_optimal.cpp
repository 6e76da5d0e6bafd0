#include "ofn/sim/time_optimal.hpp"

#include <nlopt.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <utility>

#include <Eigen/Dense>

#include "ofn/common/bspline.hpp"
#include "ofn/global_planner/global_planner.hpp"
#include "ofn/rh_optimizer/rh_optimizer.hpp"
#include "ofn/world/world.hpp"

namespace ofn::baseline {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// Variable scales: the programme's variables are O(1..10) so that SLSQP's
// unit initial Hessian is not far off.
constexpr double kLengthScale = 10.0;   // m
constexpr double kTimeScale = 10.0;     // s
constexpr double kGradientStep = 1e-4;  // m, central differences of the distance
constexpr int kMinIntervals = 4;
// A run-up that costs nothing at all is undetermined; this little weight
// keeps it purposeful without trading gate-to-gate time for it at more
// than this rate.
constexpr double kMinRunUpWeight = 1e-3;
// Initial routes longer than this times the shortest are not tried.
constexpr double kLongestGuess = 1.5;
// Programme size caps (B-spline intervals, constraint samples), so that a
// long course costs accuracy rather than unbounded time.
constexpr int kMaxIntervals = 60;
constexpr int kMaxSamples = 800;
// Gate-to-gate times this close (s) tie; the shorter whole flight wins.
constexpr double kTie = 0.01;

enum Row { kSpeedRow, kAccelRow, kVerticalRow, kForwardRow, kClearanceRow, kAltitudeRow, kRows };
const char* const kRowNames[kRows] = {"speed",         "acceleration", "vertical speed",
                                      "forward speed", "clearance",    "altitude"};

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

std::string format_seconds(double s) {
  std::ostringstream o;
  o.precision(3);
  o << std::fixed << s;
  return o.str();
}

/// What the programme needs of the course, SI and world NED.
struct Course {
  const world::World* world = nullptr;
  Vec3 start = Vec3::Zero();
  Vec3 start_velocity = Vec3::Zero();
  double start_x = 0, finish_x = 0;
  Limits limits;
  double ground_altitude = 0;
  double floor = 0;            // m above ground
  double clearance_scale = 1;  // m: clearance and altitude rows are normalised by it
};

Course make_course(const Scenario& s, const world::World& world, const BaselineSettings& settings) {
  auto fail = [&](const std::string& what) {
    throw std::invalid_argument("scenario '" + s.name + "': " + what);
  };
  if (!s.start_gate || !s.finish_gate)
    fail("no timing gates (gates.start_x and gates.finish_x); the baseline is gate to gate");
  if (!(*s.finish_gate > *s.start_gate)) fail("the finish gate must lie beyond the start gate");
  if (!(s.start_position.x() < *s.start_gate))
    fail("the start must lie before the start gate (north < gates.start_x)");
  const Limits& l = s.limits;
  if (!(l.max_speed > 0) || !(l.max_accel > 0) || !(l.max_vertical_speed > 0))
    fail("max_speed, max_accel and max_vertical_speed must be positive");
  if (!(l.clearance >= 0) || !(l.min_forward_speed >= 0))
    fail("clearance and min_forward_speed must be >= 0");
  if (l.min_forward_speed >= l.max_speed) fail("min_forward_speed must be below max_speed");
  if (s.start_velocity.norm() > l.max_speed * (1 + 1e-9) ||
      std::abs(s.start_velocity.z()) > l.max_vertical_speed * (1 + 1e-9) ||
      s.start_velocity.x() < l.min_forward_speed - 1e-9)
    fail("the start state breaks the limits (speed, vertical speed or forward speed)");
  Course c;
  c.world = &world;
  c.start = s.start_position;
  c.start_velocity = s.start_velocity;
  c.start_x = *s.start_gate;
  c.finish_x = *s.finish_gate;
  c.limits = l;
  c.ground_altitude = s.ground_altitude;
  const double start_altitude = -s.start_position.z() - s.ground_altitude;
  c.floor = settings.min_altitude >= 0 ? settings.min_altitude
                                       : std::max(0.0, std::min(l.clearance, start_altitude));
  if (start_altitude < c.floor - 1e-9) fail("the start is below the altitude floor");
  if (world.distance_to_obstacles(s.start_position) < l.clearance)
    fail("the start is within the clearance R_s of an obstacle");
  c.clearance_scale = std::max(l.clearance, 1.0);
  return c;
}

double altitude_of(const Course& c, const Vec3& p) {
  return -p.z() - c.ground_altitude;
}

/// Normalised excess of every limit at one state (<= 0: met).
std::array<double, kRows> excess(const Course& c, const Vec3& p, const Vec3& v, const Vec3& a) {
  const Limits& l = c.limits;
  std::array<double, kRows> e{};
  e[kSpeedRow] = (v.norm() - l.max_speed) / l.max_speed;
  e[kAccelRow] = (a.norm() - l.max_accel) / l.max_accel;
  e[kVerticalRow] = (std::abs(v.z()) - l.max_vertical_speed) / l.max_vertical_speed;
  e[kForwardRow] = (l.min_forward_speed - v.x()) / l.max_speed;
  e[kClearanceRow] = (l.clearance - c.world->distance_to_obstacles(p)) / c.clearance_scale;
  e[kAltitudeRow] = (c.floor - altitude_of(c, p)) / c.clearance_scale;
  return e;
}

/// The programme: one clamped uniform B-spline from the start state over a
/// free duration T, its end on the finish plane; the cost is the time from
/// its first crossing of the start plane to T. Control points 0..2 follow
/// from the start state and T, the last one's x is the finish plane.
/// Variables: T / kTimeScale, then control points 3..n-1 relative to the
/// start / kLengthScale (x, y, z each; the last point y, z only).
class Programme {
 public:
  Programme(const Course& course, int degree, int intervals, double duration_guess,
            double sample_spacing, double run_up_weight)
      : course_(course),
        basis_(degree, intervals),
        run_up_weight_(std::clamp(run_up_weight, kMinRunUpWeight, 1.0)) {
    n_ = basis_.num_control_points();
    const Eigen::RowVectorXd r1 = basis_.evaluate(0.0, 1), r2 = basis_.evaluate(0.0, 2);
    r1_ = {r1(0), r1(1)};
    r2_ = {r2(0), r2(1), r2(2)};
    const int samples =
        std::clamp(static_cast<int>(std::ceil(duration_guess / sample_spacing)), 8, kMaxSamples);
    s_.resize(samples);
    rows_.resize(samples);
    // s = 0 is the fixed start state: its rows could not change.
    for (int k = 0; k < samples; ++k) {
      s_[k] = static_cast<double>(k + 1) / samples;
      for (int d = 0; d < 3; ++d) rows_[k][d] = basis_.evaluate(s_[k], d);
    }
  }

  int num_variables() const { return 3 * n_ - 9; }
  int num_constraints() const { return kRows * static_cast<int>(s_.size()); }
  int num_control_points() const { return n_; }
  const BsplineBasis& basis() const { return basis_; }

  /// Index of control point i's axis in z, -1 when it is fixed.
  int var_index(int i, int axis) const {
    if (i < 3) return -1;
    if (i < n_ - 1) return 1 + 3 * (i - 3) + axis;
    return axis == 0 ? -1 : 1 + 3 * (n_ - 4) + axis - 1;
  }

  double duration(const double* z) const { return kTimeScale * z[0]; }

  /// Control points and the derivatives of points 1 and 2 with respect to T.
  void control_points(const double* z, std::vector<Vec3>& p, Vec3& dp1, Vec3& dp2) const {
    const double t = duration(z);
    p.assign(static_cast<size_t>(n_), course_.start);
    p[1] = (course_.start_velocity * t - r1_[0] * p[0]) / r1_[1];
    dp1 = course_.start_velocity / r1_[1];
    // Zero acceleration at the start.
    p[2] = (-r2_[0] * p[0] - r2_[1] * p[1]) / r2_[2];
    dp2 = -r2_[1] * dp1 / r2_[2];
    for (int i = 3; i < n_; ++i)
      for (int axis = 0; axis < 3; ++axis) {
        const int j = var_index(i, axis);
        if (j >= 0) p[i][axis] = course_.start[axis] + kLengthScale * z[j];
      }
    p[n_ - 1].x() = course_.finish_x;
  }

  /// Variables that put the control points at the Greville abscissae of a
  /// path sampled at constant speed (points 0..2 still from the start state).
  std::vector<double> fit(const std::function<Vec3(double)>& path_at_fraction,
                          double duration) const {
    std::vector<double> z(static_cast<size_t>(num_variables()), 0.0);
    z[0] = duration / kTimeScale;
    const auto& knots = basis_.knots();
    const int p = basis_.degree();
    for (int i = 3; i < n_; ++i) {
      double greville = 0;
      for (int k = 1; k <= p; ++k) greville += knots[static_cast<size_t>(i + k)];
      const Vec3 q = path_at_fraction(greville / p);
      for (int axis = 0; axis < 3; ++axis) {
        const int j = var_index(i, axis);
        if (j >= 0) z[j] = (q[axis] - course_.start[axis]) / kLengthScale;
      }
    }
    return z;
  }

  /// First s where the curve's x reaches x_plane (x of the curve at 1 is the finish).
  double crossing(const std::vector<Vec3>& p, double x_plane) const {
    double lo = 0, hi = 1;
    for (size_t k = 0; k < s_.size(); ++k) {
      if (eval(rows_[k][0], p).x() >= x_plane) {
        hi = s_[k];
        lo = k == 0 ? 0.0 : s_[k - 1];
        break;
      }
    }
    for (int it = 0; it < 60 && hi - lo > 1e-13; ++it) {
      const double mid = 0.5 * (lo + hi);
      (eval(basis_.evaluate(mid, 0), p).x() >= x_plane ? hi : lo) = mid;
    }
    return hi;
  }

  /// Gate-to-gate time / kTimeScale and its gradient.
  double objective(const double* z, double* grad) const {
    std::vector<Vec3> p;
    Vec3 dp1, dp2;
    control_points(z, p, dp1, dp2);
    const double t = duration(z);
    const double sg = crossing(p, course_.start_x);
    // t (1 - sg): the gate-to-gate time; t sg: the run-up.
    const double keep = 1.0 - run_up_weight_;
    const double value = t * (1.0 - keep * sg) / kTimeScale;
    if (grad) {
      std::fill(grad, grad + num_variables(), 0.0);
      const Eigen::RowVectorXd b = basis_.evaluate(sg, 0);
      const double slope = std::max(eval(basis_.evaluate(sg, 1), p).x(), 1e-6);
      // x(sg; P) = start_x: dsg/dP_ix = -B_i(sg) / x'(sg).
      for (int i = 0; i < n_; ++i) {
        const int j = var_index(i, 0);
        if (j >= 0) grad[j] = keep * t * b(i) / slope * kLengthScale / kTimeScale;
      }
      const double dsg_dt = -(b(1) * dp1.x() + b(2) * dp2.x()) / slope;
      grad[0] = 1.0 - keep * (sg + t * dsg_dt);
    }
    return value;
  }

  /// Normalised constraints (<= 0 met), rows kRows per sample, and their
  /// Jacobian (row-major, num_constraints x num_variables).
  void constraints(const double* z, double* out, double* jac) const {
    std::vector<Vec3> p;
    Vec3 dp1, dp2;
    control_points(z, p, dp1, dp2);
    const double t = duration(z);
    const int nv = num_variables();
    const Limits& l = course_.limits;
    const double v2 = l.max_speed * l.max_speed, a2 = l.max_accel * l.max_accel;
    const double w2 = l.max_vertical_speed * l.max_vertical_speed;
    const double rn = course_.clearance_scale;
    if (jac) std::fill(jac, jac + static_cast<size_t>(num_constraints()) * nv, 0.0);
    for (size_t k = 0; k < s_.size(); ++k) {
      const Vec3 c0 = eval(rows_[k][0], p), c1 = eval(rows_[k][1], p), c2 = eval(rows_[k][2], p);
      const double t2 = t * t;
      double* row = out + kRows * k;
      row[kSpeedRow] = c1.squaredNorm() / (t2 * v2) - 1.0;
      row[kAccelRow] = c2.squaredNorm() / (t2 * t2 * a2) - 1.0;
      row[kVerticalRow] = c1.z() * c1.z() / (t2 * w2) - 1.0;
      row[kForwardRow] = (l.min_forward_speed - c1.x() / t) / l.max_speed;
      // Far from everything (or with no obstacles: infinity) the row is
      // capped, inactive and flat.
      const double far = l.clearance + 10.0 * rn;
      const double d = std::min(course_.world->distance_to_obstacles(c0), far);
      row[kClearanceRow] = (l.clearance - d) / rn;
      row[kAltitudeRow] = (course_.floor - altitude_of(course_, c0)) / rn;
      if (!jac) continue;
      // Partials with respect to the position, velocity and acceleration
      // curves (in s) and T, per row.
      std::array<std::array<Vec3, 3>, kRows> partial;
      std::array<double, kRows> partial_t{};
      for (auto& pr : partial) pr = {Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};
      partial[kSpeedRow][1] = 2.0 * c1 / (t2 * v2);
      partial_t[kSpeedRow] = -2.0 * c1.squaredNorm() / (t2 * t * v2);
      partial[kAccelRow][2] = 2.0 * c2 / (t2 * t2 * a2);
      partial_t[kAccelRow] = -4.0 * c2.squaredNorm() / (t2 * t2 * t * a2);
      partial[kVerticalRow][1].z() = 2.0 * c1.z() / (t2 * w2);
      partial_t[kVerticalRow] = -2.0 * c1.z() * c1.z() / (t2 * t * w2);
      partial[kForwardRow][1].x() = -1.0 / (t * l.max_speed);
      partial_t[kForwardRow] = c1.x() / (t2 * l.max_speed);
      if (d < far) {
        Vec3 gradient;
        for (int axis = 0; axis < 3; ++axis) {
          Vec3 step = Vec3::Zero();
          step[axis] = kGradientStep;
          gradient[axis] = (course_.world->distance_to_obstacles(c0 + step) -
                            course_.world->distance_to_obstacles(c0 - step)) /
                           (2 * kGradientStep);
        }
        partial[kClearanceRow][0] = -gradient / rn;
      }
      partial[kAltitudeRow][0].z() = 1.0 / rn;
      for (int r = 0; r < kRows; ++r) {
        double* jrow = jac + (kRows * k + r) * static_cast<size_t>(nv);
        double dt = partial_t[r];
        for (int i = 0; i < n_; ++i) {
          const double b0 = rows_[k][0](i), b1 = rows_[k][1](i), b2 = rows_[k][2](i);
          if (b0 == 0 && b1 == 0 && b2 == 0) continue;
          const Vec3 dpi = b0 * partial[r][0] + b1 * partial[r][1] + b2 * partial[r][2];
          if (i == 1) dt += dpi.dot(dp1);
          if (i == 2) dt += dpi.dot(dp2);
          for (int axis = 0; axis < 3; ++axis) {
            const int j = var_index(i, axis);
            if (j >= 0) jrow[j] += kLengthScale * dpi[axis];
          }
        }
        jrow[0] = kTimeScale * dt;
      }
    }
  }

  BsplineTrajectory trajectory(const double* z) const {
    std::vector<Vec3> p;
    Vec3 dp1, dp2;
    control_points(z, p, dp1, dp2);
    return BsplineTrajectory(basis_.degree(), basis_.knots(), p, duration(z));
  }

 private:
  static Vec3 eval(const Eigen::RowVectorXd& row, const std::vector<Vec3>& p) {
    Vec3 v = Vec3::Zero();
    for (int i = 0; i < row.size(); ++i)
      if (row(i) != 0) v += row(i) * p[static_cast<size_t>(i)];
    return v;
  }

  const Course& course_;
  BsplineBasis basis_;
  double run_up_weight_;
  int n_ = 0;
  std::array<double, 2> r1_{};
  std::array<double, 3> r2_{};
  std::vector<double> s_;
  std::vector<std::array<Eigen::RowVectorXd, 3>> rows_;
};

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
