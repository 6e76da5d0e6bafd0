#include "ofn/sim/time_optimal_programme.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace ofn::baseline {

namespace {

constexpr double kGradientStep = 1e-4;  // m, central differences of the distance
// A run-up that costs nothing at all is undetermined; this little weight
// keeps it purposeful without trading gate-to-gate time for it at more
// than this rate.
constexpr double kMinRunUpWeight = 1e-3;
// Constraint samples at most, so that a long course costs accuracy rather
// than unbounded time.
constexpr int kMaxSamples = 800;

}  // namespace

const char* const kRowNames[kRows] = {"speed",         "acceleration", "vertical speed",
                                      "forward speed", "clearance",    "altitude"};

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

Programme::Programme(const Course& course, int degree, int intervals, double duration_guess,
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

int Programme::var_index(int i, int axis) const {
  if (i < 3) return -1;
  if (i < n_ - 1) return 1 + 3 * (i - 3) + axis;
  return axis == 0 ? -1 : 1 + 3 * (n_ - 4) + axis - 1;
}

void Programme::control_points(const double* z, std::vector<Vec3>& p, Vec3& dp1, Vec3& dp2) const {
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

std::vector<double> Programme::fit(const std::function<Vec3(double)>& path_at_fraction,
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

double Programme::crossing(const std::vector<Vec3>& p, double x_plane) const {
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

double Programme::objective(const double* z, double* grad) const {
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

void Programme::constraints(const double* z, double* out, double* jac) const {
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

BsplineTrajectory Programme::trajectory(const double* z) const {
  std::vector<Vec3> p;
  Vec3 dp1, dp2;
  control_points(z, p, dp1, dp2);
  return BsplineTrajectory(basis_.degree(), basis_.knots(), p, duration(z));
}

Vec3 Programme::eval(const Eigen::RowVectorXd& row, const std::vector<Vec3>& p) {
  Vec3 v = Vec3::Zero();
  for (int i = 0; i < row.size(); ++i)
    if (row(i) != 0) v += row(i) * p[static_cast<size_t>(i)];
  return v;
}

}  // namespace ofn::baseline
