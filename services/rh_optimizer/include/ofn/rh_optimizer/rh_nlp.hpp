#pragma once
// The nonlinear programme behind RhOptimizer (paper 4.1): scaled variables,
// cost, constraints and their analytic gradients, exposed so that they can
// be checked against finite differences.
//
// Variables z (all O(1)): the free control points of x, y, z in the guidance
// frame relative to the start position, in units of kLengthScale, axis by
// axis (control points 3..n-1 of x, then of y, then of z), and last the
// final time T in units of kTimeScale. Control points 0..2 follow from the
// initial state (Eq. 5) and T.

#include <array>
#include <optional>
#include <vector>

#include <Eigen/Dense>

#include "ofn/common/bspline.hpp"
#include "ofn/rh_optimizer/rh_optimizer.hpp"

namespace ofn::rh {

/// The path constraints of one trajectory point, in the order of the rows
/// the programme lays out per collocation point (clearance only when the
/// problem has a clearance query).
enum PointConstraint {
  kClearanceRow = 0,
  kForwardSpeedRow,
  kClimbSpeedRow,    // -w <= max_vertical_speed (w: the world's down speed)
  kDescentSpeedRow,  // w <= max_vertical_speed
  kTotalSpeedRow,
  kAccelerationRow,
  kCommandedAccelerationRow,
  kAltitudeRow,
  kNumPointConstraints
};

/// The problem's constraints at one point from its guidance-frame state
/// (position relative to the start, velocity, acceleration, jerk): shared by
/// the programme and by the verification resampling.
class PointConstraintModel {
 public:
  PointConstraintModel(const RhSettings& settings, const RhProblem& problem,
                       double start_clearance);

  /// Normalised values (<= 0 met), their partial derivatives with respect
  /// to (derivative order k, guidance axis), and the derivative of each
  /// value with respect to the time t of the point (the clearance
  /// requirement grows with t when the start is inside it; the forward
  /// speed's reserve builds up over kForwardReserveRamp).
  struct Result {
    std::array<double, kNumPointConstraints> value{};
    std::array<Eigen::Matrix<double, 4, 3>, kNumPointConstraints> partial;
    std::array<double, kNumPointConstraints> time_derivative{};
  };
  void evaluate(const std::array<Vec3, 4>& state, double t, bool with_partials, Result& out) const;

  /// Clearance needed at time t from the start.
  double required_clearance(double t, double* derivative = nullptr) const;
  bool has_clearance() const { return static_cast<bool>(clearance_); }

 private:
  Mat3 world_from_guidance_;
  Vec3 start_world_;
  ClearanceQuery clearance_;
  double planned_clearance_;
  double start_clearance_;
  double clearance_norm_;
  Vec3 tau_;
  double max_speed_;
  double start_speed_;  // |v0|, at most max_speed_
  double max_vertical_speed_, min_forward_speed_, max_accel_;
  double forward_speed_reserve_;  // m/s; 0 when the forward speed rule is relaxed
  double min_altitude_, altitude_norm_, ground_altitude_;
};

/// Basis rows evaluated once per settings.
struct RhTables {
  explicit RhTables(const RhSettings& settings);

  int num_control_points = 0;
  int free_per_axis = 0;
  int collocation = 0;
  std::array<Eigen::MatrixXd, 4> collocation_rows;  // derivative k at s_i = (i+1)/N
  Eigen::MatrixXd quadrature_rows;                  // values at the Gauss points
  Eigen::VectorXd quadrature_weights;               // over s in [0, 1], summing to 1
  Eigen::MatrixXd fit_rows;                         // values at equally spaced s for guess fits
  Eigen::MatrixXd fit_solver;                       // least-squares map onto the free points
  // Control points 1 and 2 from the initial state: c1 = c0 + a1 v0 T,
  // c2 = c0 + b1 v0 T + b2 a0 T^2.
  double c1_velocity = 0, c2_velocity = 0, c2_acceleration = 0;
};

class RhNlp {
 public:
  static constexpr double kLengthScale = 10.0;  // m per control-point unit
  static constexpr double kTimeScale = 10.0;    // s per final-time unit

  RhNlp(const RhSettings& settings, const BsplineBasis& basis);

  /// Prepares a problem (must be finite and its limits positive).
  void set_problem(const RhProblem& problem);
  /// The objective is J / cost_scale (J of Eq. 1, unscaled).
  void set_cost_scale(double scale) { cost_scale_ = scale; }
  double cost_scale() const { return cost_scale_; }

  int num_variables() const { return 3 * tables_.free_per_axis + 1; }
  /// The terminal speed rows (Eq. 6), the last of the inequalities.
  static constexpr int kNumTerminalInequalities = 4;
  int num_inequalities() const;
  int num_equalities() const;
  /// Bounds of z (T bounded by the settings; control points generously).
  void bounds(std::vector<double>& lower, std::vector<double>& upper) const;

  /// Scaled objective; gradient (num_variables) when non-null.
  double objective(const double* z, double* gradient);
  /// Unscaled cost (Eq. 1) at z.
  double cost(const double* z);
  /// Normalised constraint values (<= 0 met, = 0 for equalities) and, when
  /// non-null, the row-major Jacobian (rows x num_variables).
  void inequalities(const double* z, double* values, double* jacobian);
  void equalities(const double* z, double* values, double* jacobian);
  /// Worst violation of any constraint at z (inequality value or |equality|).
  double max_violation(const double* z);

  /// Variables whose free control points fit the guess positions in the
  /// least-squares sense, T = guess duration clamped to the bounds.
  Eigen::VectorXd fit(const InitialGuess& guess) const;
  /// The world-NED trajectory of z.
  BsplineTrajectory trajectory(const double* z) const;

  double start_clearance() const { return start_clearance_; }
  const RhTables& tables() const { return tables_; }

 private:
  void evaluate(const double* z);
  // Control points (n x 3, guidance, relative to the start) for duration T
  // with the free ones from z; the derivative of rows 1 and 2 with respect
  // to T into the two vectors when non-null.
  void control_points(const double* z, double duration, Eigen::MatrixXd& points,
                      Vec3* row1_time_derivative, Vec3* row2_time_derivative) const;
  // One Jacobian row of a constraint at collocation point `point` from its
  // partials with respect to the state there.
  void jacobian_row(int point, const Eigen::Matrix<double, 4, 3>& partial,
                    double extra_time_derivative, double* row) const;

  RhSettings settings_;
  std::vector<double> knots_;
  RhTables tables_;

  // Problem.
  Mat3 world_from_guidance_ = Mat3::Identity();
  Vec3 start_world_ = Vec3::Zero();
  Vec3 start_velocity_ = Vec3::Zero();      // guidance
  Vec3 start_acceleration_ = Vec3::Zero();  // guidance
  Vec3 target_ = Vec3::Zero();              // guidance, relative to the start
  double terminal_x_ = 0;                   // guidance, relative to the start
  bool stop_at_target_ = false;             // RhProblem::stop_at_target
  double max_speed_ = 1, max_vertical_speed_ = 1, max_accel_ = 1;
  double start_clearance_ = 0;
  bool has_clearance_ = false;
  std::optional<PointConstraintModel> model_;
  double cost_scale_ = 1.0;

  // Evaluation cache at the last z.
  bool cached_ = false;
  Eigen::VectorXd cached_z_;
  double cost_ = 0;
  Eigen::VectorXd cost_gradient_;
  Eigen::VectorXd ineq_values_, eq_values_;
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> ineq_jacobian_,
      eq_jacobian_;
  // Scratch.
  Eigen::MatrixXd points_;                   // n x 3 control points
  std::array<Eigen::MatrixXd, 4> state_;     // N x 3, derivative k at the collocation points
  std::array<Eigen::MatrixXd, 4> state_dt_;  // N x 3, its derivative with respect to T
  Eigen::MatrixXd quad_state_, quad_state_dt_, quad_residual_;  // Q x 3
  double duration_ = 1;                                         // T at the cached z
  PointConstraintModel::Result point_;
};

}  // namespace ofn::rh
