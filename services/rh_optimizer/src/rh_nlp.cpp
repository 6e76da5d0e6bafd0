#include "ofn/rh_optimizer/rh_nlp.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <Eigen/Eigenvalues>

namespace ofn::rh {
namespace {

// Gauss-Legendre nodes and weights on [-1, 1] (Golub-Welsch).
void gauss_legendre(int points, Eigen::VectorXd& nodes, Eigen::VectorXd& weights) {
  Eigen::MatrixXd jacobi = Eigen::MatrixXd::Zero(points, points);
  for (int i = 1; i < points; ++i) {
    const double b = i / std::sqrt(4.0 * i * i - 1.0);
    jacobi(i, i - 1) = b;
    jacobi(i - 1, i) = b;
  }
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> solver(jacobi);
  nodes = solver.eigenvalues();
  weights = 2.0 * solver.eigenvectors().row(0).transpose().array().square();
}

}  // namespace

/// Below this start speed (m/s) a plan starts from a hover (see
/// required_clearance).
constexpr double kHoverStartSpeed = 0.3;

/// Time (s) over which the forward speed's reserve builds up from the start:
/// a start flying sideways with u = 0 (the last plan, or a plan made before
/// the reserve) cannot have it at once.
constexpr double kForwardReserveRamp = 1.0;

/// Speed (m/s) about which the forward speed's reserve sets in: the path
/// heading holds below 1 m/s (the controller's path_heading.min_speed), and
/// with it the heading turns that make the tracking error.
constexpr double kForwardReserveSpeed = 1.0;

// ---------------------------------------------------------------------------

PointConstraintModel::PointConstraintModel(const RhSettings& settings, const RhProblem& problem,
                                           double start_clearance)
    : world_from_guidance_(problem.frame.world_from_guidance),
      start_world_(problem.position),
      clearance_(problem.clearance),
      planned_clearance_(problem.limits.clearance + settings.clearance_margin),
      start_clearance_(start_clearance),
      clearance_norm_(std::max(problem.limits.clearance + settings.clearance_margin, 1.0)),
      tau_(settings.time_constants),
      max_speed_((1.0 - settings.speed_margin) * problem.limits.max_speed),
      start_speed_(std::min(problem.velocity.norm(), max_speed_)),
      max_vertical_speed_((1.0 - settings.speed_margin) * problem.limits.max_vertical_speed),
      min_forward_speed_(problem.limits.min_forward_speed),
      max_accel_((1.0 - settings.accel_margin) * problem.limits.max_accel),
      // Only the forward speed rule of Eq. 8 gets the reserve; a dead-end
      // escape relaxes the rule to -max_speed and needs none.
      forward_speed_reserve_(
          problem.limits.min_forward_speed >= 0.0 ? settings.forward_speed_reserve : 0.0),
      min_altitude_(settings.min_altitude),
      altitude_norm_(std::max(settings.min_altitude, 1.0)),
      ground_altitude_(settings.ground_altitude) {}

double PointConstraintModel::required_clearance(double t, double* derivative) const {
  if (derivative) *derivative = 0;
  if (start_clearance_ >= planned_clearance_) return planned_clearance_;
  // At the speed limit from t = 0, except from a hover: a vehicle at rest
  // cannot meet that ramp, and from a stop that ended a few centimetres
  // inside R_plan every plan was infeasible and the vehicle stayed. From a
  // hover the requirement grows as far as the vehicle could get: nothing
  // for the largest acceleration time constant (the commanded-acceleration
  // limit of Eq. 4 holds the acceleration back about that long), then at
  // half the acceleration limit up to the speed limit. (Relaxing it for a
  // moving start too let dense-field plans linger near obstacles: fewer
  // fields succeeded.)
  double gained = max_speed_ * t, rate = max_speed_;
  if (start_speed_ < kHoverStartSpeed) {
    const double delay = tau_.maxCoeff();
    const double accel = 0.5 * max_accel_;
    const double moving = std::max(0.0, t - delay);
    const double t_full = accel > 0 ? max_speed_ / accel : 0.0;
    gained = moving < t_full ? 0.5 * accel * moving * moving : max_speed_ * (moving - 0.5 * t_full);
    rate = moving < t_full ? accel * moving : max_speed_;
  }
  const double climbing = std::max(start_clearance_, 0.0) + gained;
  if (climbing >= planned_clearance_) return planned_clearance_;
  if (derivative) *derivative = rate;
  return climbing;
}

void PointConstraintModel::evaluate(const std::array<Vec3, 4>& state, double t, bool with_partials,
                                    Result& out) const {
  const Vec3& position = state[0];
  const Vec3& velocity = state[1];
  const Vec3& accel = state[2];
  const Vec3& jerk = state[3];
  if (with_partials)
    for (auto& p : out.partial) p.setZero();
  out.time_derivative.fill(0.0);
  const Vec3 world = start_world_ + world_from_guidance_ * position;

  if (clearance_) {
    const mapping::DistanceSample sample = clearance_(world);
    double required_rate = 0;
    const double required = required_clearance(t, &required_rate);
    out.value[kClearanceRow] = (required - sample.distance) / clearance_norm_;
    if (with_partials) {
      out.partial[kClearanceRow].row(0) =
          -(world_from_guidance_.transpose() * sample.gradient).transpose() / clearance_norm_;
      out.time_derivative[kClearanceRow] = required_rate / clearance_norm_;
    }
  } else {
    out.value[kClearanceRow] = -1.0;
  }

  // u >= min_forward_speed + r h^2 / (h^2 + v_r^2), h the horizontal
  // speed: a plan flying sideways keeps a little forward speed (nearly r
  // once faster than v_r) for the controller's tracking error, which the
  // heading's turns make and which hardly grows with speed. Planned at
  // u = 0 exactly, sideways flights at 5-8 ft/s drifted back at -0.24 to
  // -0.25 ft/s while the heading turned at up to 57 deg/s, beyond the
  // benchmarks' 2 % (dense seeds 8, 16 and 20). Zero at a hover and in a
  // vertical climb (the heading holds there), so the vehicle may still stop
  // or climb in place. Counted on the 3-D speed, every solve failed for 2 s
  // while the tree course climbed towards the tree, and it braked (50.0 s
  // gate to gate against 41.4).
  const Vec3 world_down = world_from_guidance_.row(2).transpose();
  const double down_speed = world_down.dot(velocity);
  const double ramp = std::min(1.0, std::max(t, 0.0) / kForwardReserveRamp);
  const double speed_sq = velocity.squaredNorm() - down_speed * down_speed;
  const double knee_sq = kForwardReserveSpeed * kForwardReserveSpeed;
  const double reserve = forward_speed_reserve_ * speed_sq / (speed_sq + knee_sq);
  out.value[kForwardSpeedRow] = (min_forward_speed_ + ramp * reserve - velocity.x()) / max_speed_;
  if (t < kForwardReserveRamp)
    out.time_derivative[kForwardSpeedRow] = reserve / (kForwardReserveRamp * max_speed_);
  // The vertical speed limit is the world's: on a climbing or descending leg
  // (an escape over a wall) the guidance frame is pitched and its z axis is
  // not the vertical. Held on the guidance z, a steep escape climbed faster
  // than the limit and the commit gate refused every plan.
  out.value[kClimbSpeedRow] = (-down_speed - max_vertical_speed_) / max_vertical_speed_;
  out.value[kDescentSpeedRow] = (down_speed - max_vertical_speed_) / max_vertical_speed_;
  out.value[kTotalSpeedRow] = velocity.squaredNorm() / (max_speed_ * max_speed_) - 1.0;
  const double accel_sq = max_accel_ * max_accel_;
  out.value[kAccelerationRow] = accel.squaredNorm() / accel_sq - 1.0;
  const Vec3 commanded = accel + tau_.cwiseProduct(jerk);
  out.value[kCommandedAccelerationRow] = commanded.squaredNorm() / accel_sq - 1.0;
  const double altitude = -world.z() - ground_altitude_;
  out.value[kAltitudeRow] = (min_altitude_ - altitude) / altitude_norm_;

  if (!with_partials) return;
  {
    // d(h^2)/dv = 2 (v - (down . v) down), down the world's vertical.
    const double denominator = (speed_sq + knee_sq) * (speed_sq + knee_sq);
    out.partial[kForwardSpeedRow].row(1) =
        (2.0 * ramp * forward_speed_reserve_ * knee_sq / denominator) *
        (velocity - down_speed * world_down).transpose() / max_speed_;
  }
  out.partial[kForwardSpeedRow](1, 0) -= 1.0 / max_speed_;
  out.partial[kClimbSpeedRow].row(1) = -world_from_guidance_.row(2) / max_vertical_speed_;
  out.partial[kDescentSpeedRow].row(1) = world_from_guidance_.row(2) / max_vertical_speed_;
  out.partial[kTotalSpeedRow].row(1) = 2.0 * velocity.transpose() / (max_speed_ * max_speed_);
  out.partial[kAccelerationRow].row(2) = 2.0 * accel.transpose() / accel_sq;
  out.partial[kCommandedAccelerationRow].row(2) = 2.0 * commanded.transpose() / accel_sq;
  out.partial[kCommandedAccelerationRow].row(3) =
      2.0 * commanded.cwiseProduct(tau_).transpose() / accel_sq;
  out.partial[kAltitudeRow].row(0) = world_from_guidance_.row(2) / altitude_norm_;
}

// ---------------------------------------------------------------------------

RhTables::RhTables(const RhSettings& settings) {
  const BsplineBasis basis(settings.degree, settings.intervals);
  num_control_points = basis.num_control_points();
  free_per_axis = num_control_points - 3;
  collocation = settings.collocation_points;
  for (int k = 0; k < 4; ++k) {
    collocation_rows[k].resize(collocation, num_control_points);
    for (int i = 0; i < collocation; ++i)
      collocation_rows[k].row(i) = basis.evaluate(static_cast<double>(i + 1) / collocation, k);
  }

  // degree + 1 Gauss points per knot interval integrate the squared
  // position error (a polynomial of degree 2 * degree) exactly.
  const int per_interval = settings.degree + 1;
  Eigen::VectorXd nodes, weights;
  gauss_legendre(per_interval, nodes, weights);
  const int intervals = settings.intervals;
  quadrature_rows.resize(intervals * per_interval, num_control_points);
  quadrature_weights.resize(intervals * per_interval);
  for (int j = 0; j < intervals; ++j)
    for (int q = 0; q < per_interval; ++q) {
      const double s = (j + 0.5 * (nodes(q) + 1.0)) / intervals;
      quadrature_rows.row(j * per_interval + q) = basis.evaluate(s, 0);
      quadrature_weights(j * per_interval + q) = 0.5 * weights(q) / intervals;
    }

  const int fit_points = 4 * num_control_points;
  fit_rows.resize(fit_points, num_control_points);
  for (int k = 0; k < fit_points; ++k)
    fit_rows.row(k) = basis.evaluate(static_cast<double>(k) / (fit_points - 1), 0);
  fit_solver = fit_rows.rightCols(free_per_axis).completeOrthogonalDecomposition().pseudoInverse();

  const Eigen::RowVectorXd d1 = basis.evaluate(0.0, 1);
  const Eigen::RowVectorXd d2 = basis.evaluate(0.0, 2);
  c1_velocity = 1.0 / d1(1);
  c2_velocity = -d2(1) * c1_velocity / d2(2);
  c2_acceleration = 1.0 / d2(2);
}

// ---------------------------------------------------------------------------

RhNlp::RhNlp(const RhSettings& settings, const BsplineBasis& basis)
    : settings_(settings), knots_(basis.knots()), tables_(settings) {
  const int n = tables_.num_control_points;
  const int N = tables_.collocation;
  const int Q = static_cast<int>(tables_.quadrature_weights.size());
  points_.resize(n, 3);
  for (int k = 0; k < 4; ++k) {
    state_[k].resize(N, 3);
    state_dt_[k].resize(N, 3);
  }
  quad_state_.resize(Q, 3);
  quad_state_dt_.resize(Q, 3);
  quad_residual_.resize(Q, 3);
  cached_z_.resize(num_variables());
  cost_gradient_.resize(num_variables());
}

void RhNlp::set_problem(const RhProblem& problem) {
  world_from_guidance_ = problem.frame.world_from_guidance;
  start_world_ = problem.position;
  const Mat3 guidance_from_world = world_from_guidance_.transpose();
  start_velocity_ = guidance_from_world * problem.velocity;
  // The start acceleration is the last plan's at this instant. Nothing
  // bounds a plan between its start and its first collocation point, so it
  // can rise above the reserve there, and the next plan, starting from that,
  // higher still: on random field 257 the reference rode at 102 % of the
  // limit for a second. Held inside the reserve (a step in the reference of
  // at most the reserve), the start breaks that chain.
  const double accel_reserve = (1.0 - settings_.accel_margin) * problem.limits.max_accel;
  start_acceleration_ = clamp_norm(guidance_from_world * problem.acceleration, accel_reserve);
  target_ = guidance_from_world * (problem.target - problem.position);
  terminal_x_ = problem.terminal_x - problem.frame.to_guidance(problem.position).x();
  stop_at_target_ = problem.stop_at_target;
  // Bounds of the terminal speed rows and of the control points: a start
  // speed already inside the reserve (up to the limit itself) sets them.
  // The path constraints (PointConstraintModel) keep the plain reserve:
  // relieved there too, bench5 commanded 103 % of the acceleration limit.
  // The acceleration needs no such relief, its start being held inside.
  const auto with_reserve = [](double limit, double margin, double at_start) {
    return std::max((1.0 - margin) * limit, std::min(std::abs(at_start), limit));
  };
  max_speed_ =
      with_reserve(problem.limits.max_speed, settings_.speed_margin, problem.velocity.norm());
  max_vertical_speed_ =
      with_reserve(problem.limits.max_vertical_speed, settings_.speed_margin, problem.velocity.z());
  max_accel_ = accel_reserve;
  has_clearance_ = static_cast<bool>(problem.clearance);
  start_clearance_ = has_clearance_ ? problem.clearance(problem.position).distance
                                    : std::numeric_limits<double>::infinity();
  model_.emplace(settings_, problem, start_clearance_);

  ineq_values_.resize(num_inequalities());
  eq_values_.resize(num_equalities());
  ineq_jacobian_.resize(num_inequalities(), num_variables());
  eq_jacobian_.resize(num_equalities(), num_variables());
  cached_ = false;
}

int RhNlp::num_inequalities() const {
  const int per_point = kNumPointConstraints - (has_clearance_ ? 0 : 1);
  return tables_.collocation * per_point + kNumTerminalInequalities;
}

int RhNlp::num_equalities() const {
  return 2 + (settings_.zero_terminal_accel ? 3 : 0) + (stop_at_target_ ? 4 : 0);
}

void RhNlp::bounds(std::vector<double>& lower, std::vector<double>& upper) const {
  const int nv = num_variables();
  const double reach =
      (2.0 * settings_.max_duration * max_speed_ + std::abs(terminal_x_) + 100.0) / kLengthScale;
  lower.assign(static_cast<size_t>(nv), -reach);
  upper.assign(static_cast<size_t>(nv), reach);
  lower.back() = settings_.min_duration / kTimeScale;
  upper.back() = settings_.max_duration / kTimeScale;
}

void RhNlp::control_points(const double* z, double duration, Eigen::MatrixXd& points,
                           Vec3* row1_time_derivative, Vec3* row2_time_derivative) const {
  const int f = tables_.free_per_axis;
  points.row(0).setZero();
  points.row(1) = (tables_.c1_velocity * duration * start_velocity_).transpose();
  points.row(2) = (tables_.c2_velocity * duration * start_velocity_ +
                   tables_.c2_acceleration * duration * duration * start_acceleration_)
                      .transpose();
  for (int a = 0; a < 3; ++a)
    for (int j = 0; j < f; ++j) points(3 + j, a) = kLengthScale * z[a * f + j];
  if (row1_time_derivative) *row1_time_derivative = tables_.c1_velocity * start_velocity_;
  if (row2_time_derivative)
    *row2_time_derivative = tables_.c2_velocity * start_velocity_ +
                            2.0 * tables_.c2_acceleration * duration * start_acceleration_;
}

void RhNlp::evaluate(const double* z) {
  const int nv = num_variables();
  if (cached_ && std::equal(z, z + nv, cached_z_.data())) return;
  std::copy(z, z + nv, cached_z_.data());
  cached_ = true;

  const double T = std::max(kTimeScale * z[nv - 1], 1e-6);
  duration_ = T;
  Vec3 dp1, dp2;
  control_points(z, T, points_, &dp1, &dp2);

  const int f = tables_.free_per_axis;
  const int N = tables_.collocation;
  double inv_tk = 1.0;
  for (int k = 0; k < 4; ++k) {
    const Eigen::MatrixXd& rows = tables_.collocation_rows[k];
    state_[k].noalias() = rows * points_;
    state_[k] *= inv_tk;
    state_dt_[k].noalias() = rows.col(1) * dp1.transpose();
    state_dt_[k].noalias() += rows.col(2) * dp2.transpose();
    state_dt_[k] *= inv_tk;
    state_dt_[k] -= (k / T) * state_[k];
    inv_tk /= T;
  }

  // Cost (Eq. 1): J = T * sum_q w_q sum_a ((target_a - p_a) / R_a)^2.
  const Eigen::MatrixXd& qrows = tables_.quadrature_rows;
  const Eigen::VectorXd& qw = tables_.quadrature_weights;
  quad_state_.noalias() = qrows * points_;
  quad_state_dt_.noalias() = qrows.col(1) * dp1.transpose();
  quad_state_dt_.noalias() += qrows.col(2) * dp2.transpose();
  const Vec3 inv_weight_sq = settings_.weights.cwiseProduct(settings_.weights).cwiseInverse();
  double integral = 0;
  double integral_dt = 0;
  for (int q = 0; q < quad_state_.rows(); ++q) {
    for (int a = 0; a < 3; ++a) {
      const double error = target_(a) - quad_state_(q, a);
      integral += qw(q) * error * error * inv_weight_sq(a);
      quad_residual_(q, a) = -2.0 * qw(q) * error * inv_weight_sq(a);
      integral_dt += quad_residual_(q, a) * quad_state_dt_(q, a);
    }
  }
  cost_ = T * integral + settings_.time_weight * T;
  for (int a = 0; a < 3; ++a)
    cost_gradient_.segment(a * f, f).noalias() =
        (T * kLengthScale) * qrows.rightCols(f).transpose() * quad_residual_.col(a);
  cost_gradient_(nv - 1) = kTimeScale * (integral + T * integral_dt + settings_.time_weight);

  // Path constraints at the collocation points after the start.
  const PointConstraintModel& model = *model_;
  int row = 0;
  std::array<Vec3, 4> state;
  for (int i = 0; i < N; ++i) {
    for (int k = 0; k < 4; ++k) state[k] = state_[k].row(i).transpose();
    const double s = static_cast<double>(i + 1) / N;
    model.evaluate(state, s * T, true, point_);
    for (int c = 0; c < kNumPointConstraints; ++c) {
      if (c == kClearanceRow && !has_clearance_) continue;
      ineq_values_(row) = point_.value[c];
      const double extra = point_.time_derivative[c] * s;
      jacobian_row(i, point_.partial[c], extra, ineq_jacobian_.row(row).data());
      ++row;
    }
  }

  // Terminal (Eq. 6) at s = 1, the last collocation point.
  const int last = N - 1;
  const double u = state_[1](last, 0);
  const double v = state_[1](last, 1);
  Eigen::Matrix<double, 4, 3> partial;
  auto terminal_row = [&](Eigen::Ref<Eigen::VectorXd> values, auto& jacobian, int r, double value,
                          int k, int a, double slope) {
    values(r) = value;
    partial.setZero();
    partial(k, a) = slope;
    jacobian_row(last, partial, 0.0, jacobian.row(r).data());
  };
  terminal_row(ineq_values_, ineq_jacobian_, row++, -u / max_speed_, 1, 0, -1.0 / max_speed_);
  terminal_row(ineq_values_, ineq_jacobian_, row++, u / max_speed_ - 1.0, 1, 0, 1.0 / max_speed_);
  terminal_row(ineq_values_, ineq_jacobian_, row++, v / max_speed_ - 1.0, 1, 1, 1.0 / max_speed_);
  terminal_row(ineq_values_, ineq_jacobian_, row++, -v / max_speed_ - 1.0, 1, 1, -1.0 / max_speed_);

  terminal_row(eq_values_, eq_jacobian_, 0, (state_[0](last, 0) - terminal_x_) / kLengthScale, 0, 0,
               1.0 / kLengthScale);
  terminal_row(eq_values_, eq_jacobian_, 1, state_[1](last, 2) / max_vertical_speed_, 1, 2,
               1.0 / max_vertical_speed_);
  int eq_row = 2;
  if (settings_.zero_terminal_accel)
    for (int a = 0; a < 3; ++a)
      terminal_row(eq_values_, eq_jacobian_, eq_row++, state_[2](last, a) / max_accel_, 2, a,
                   1.0 / max_accel_);
  if (stop_at_target_) {
    // At rest on the target: its y and z, no forward or sideways speed (x
    // and the vertical speed are the rows above).
    for (int a = 1; a < 3; ++a)
      terminal_row(eq_values_, eq_jacobian_, eq_row++,
                   (state_[0](last, a) - target_(a)) / kLengthScale, 0, a, 1.0 / kLengthScale);
    for (int a = 0; a < 2; ++a)
      terminal_row(eq_values_, eq_jacobian_, eq_row++, state_[1](last, a) / max_speed_, 1, a,
                   1.0 / max_speed_);
  }
}

void RhNlp::jacobian_row(int point, const Eigen::Matrix<double, 4, 3>& partial,
                         double extra_time_derivative, double* row) const {
  const int f = tables_.free_per_axis;
  const int nv = num_variables();
  std::fill(row, row + nv, 0.0);
  double time_derivative = extra_time_derivative;
  double inv_tk = kLengthScale;
  for (int k = 0; k < 4; ++k) {
    const Eigen::MatrixXd& rows = tables_.collocation_rows[k];
    for (int a = 0; a < 3; ++a) {
      const double g = partial(k, a);
      if (g == 0.0) continue;
      time_derivative += g * state_dt_[k](point, a);
      const double coefficient = g * inv_tk;
      double* block = row + a * f;
      for (int j = 0; j < f; ++j) block[j] += coefficient * rows(point, 3 + j);
    }
    inv_tk /= duration_;
  }
  row[nv - 1] = kTimeScale * time_derivative;
}

double RhNlp::objective(const double* z, double* gradient) {
  evaluate(z);
  if (gradient) {
    const double inv = 1.0 / cost_scale_;
    for (int j = 0; j < num_variables(); ++j) gradient[j] = cost_gradient_(j) * inv;
  }
  return cost_ / cost_scale_;
}

double RhNlp::cost(const double* z) {
  evaluate(z);
  return cost_;
}

void RhNlp::inequalities(const double* z, double* values, double* jacobian) {
  evaluate(z);
  std::copy(ineq_values_.data(), ineq_values_.data() + ineq_values_.size(), values);
  if (jacobian)
    std::copy(ineq_jacobian_.data(), ineq_jacobian_.data() + ineq_jacobian_.size(), jacobian);
}

void RhNlp::equalities(const double* z, double* values, double* jacobian) {
  evaluate(z);
  std::copy(eq_values_.data(), eq_values_.data() + eq_values_.size(), values);
  if (jacobian) std::copy(eq_jacobian_.data(), eq_jacobian_.data() + eq_jacobian_.size(), jacobian);
}

double RhNlp::max_violation(const double* z) {
  evaluate(z);
  double worst = ineq_values_.size() ? ineq_values_.maxCoeff() : -1.0;
  if (eq_values_.size()) worst = std::max(worst, eq_values_.cwiseAbs().maxCoeff());
  return worst;
}

Eigen::VectorXd RhNlp::fit(const InitialGuess& guess) const {
  const int nv = num_variables();
  const int f = tables_.free_per_axis;
  Eigen::VectorXd z(nv);
  const double T = std::clamp(guess.duration, settings_.min_duration, settings_.max_duration);
  z(nv - 1) = T / kTimeScale;

  Eigen::MatrixXd points(tables_.num_control_points, 3);
  control_points(z.data(), T, points, nullptr, nullptr);
  const int K = static_cast<int>(tables_.fit_rows.rows());
  const int P = static_cast<int>(guess.positions.size());
  const Mat3 guidance_from_world = world_from_guidance_.transpose();
  Eigen::MatrixXd targets(K, 3);
  for (int k = 0; k < K; ++k) {
    const double index = P > 1 ? static_cast<double>(k) / (K - 1) * (P - 1) : 0.0;
    const int lo = std::min(static_cast<int>(index), std::max(P - 2, 0));
    const int hi = std::min(lo + 1, P - 1);
    const double w = std::clamp(index - lo, 0.0, 1.0);
    const Vec3 world = (1.0 - w) * guess.positions[static_cast<size_t>(lo)] +
                       w * guess.positions[static_cast<size_t>(hi)];
    targets.row(k) = (guidance_from_world * (world - start_world_)).transpose();
  }
  targets -= tables_.fit_rows.leftCols(3) * points.topRows(3);
  const Eigen::MatrixXd free = tables_.fit_solver * targets / kLengthScale;
  for (int a = 0; a < 3; ++a) z.segment(a * f, f) = free.col(a);
  return z;
}

BsplineTrajectory RhNlp::trajectory(const double* z) const {
  const int nv = num_variables();
  const double T = std::max(kTimeScale * z[nv - 1], 1e-6);
  Eigen::MatrixXd points(tables_.num_control_points, 3);
  control_points(z, T, points, nullptr, nullptr);
  std::vector<Vec3> world(static_cast<size_t>(points.rows()));
  for (int j = 0; j < points.rows(); ++j)
    world[static_cast<size_t>(j)] = start_world_ + world_from_guidance_ * points.row(j).transpose();
  return BsplineTrajectory(settings_.degree, knots_, std::move(world), T);
}

}  // namespace ofn::rh
