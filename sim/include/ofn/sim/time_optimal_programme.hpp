#pragma once
// The time-optimal baseline's programme (time_optimal.hpp): one clamped
// uniform B-spline from the start state over a free duration, the
// gate-to-gate time as its cost, every limit sampled as a normalised
// constraint, with analytic gradients for SLSQP. Pure core: world NED, SI
// units.

#include <array>
#include <functional>
#include <vector>

#include <Eigen/Dense>

#include "ofn/common/bspline.hpp"
#include "ofn/common/scenario.hpp"
#include "ofn/sim/time_optimal.hpp"
#include "ofn/world/world.hpp"

namespace ofn::baseline {

/// The limits a state must meet, one constraint row each per sample.
enum LimitRow {
  kSpeedRow,
  kAccelRow,
  kVerticalRow,
  kForwardRow,
  kClearanceRow,
  kAltitudeRow,
  kRows
};
/// The rows' names, for reports.
extern const char* const kRowNames[kRows];

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

/// The course of a scenario; throws std::invalid_argument (naming the
/// scenario) when it has no gates, its start breaks a limit or lies within
/// R_s of an obstacle or below the altitude floor.
Course make_course(const Scenario& s, const world::World& world, const BaselineSettings& settings);

/// m above ground of the point p.
double altitude_of(const Course& c, const Vec3& p);

/// Normalised excess of every limit at one state (<= 0: met).
std::array<double, kRows> excess(const Course& c, const Vec3& p, const Vec3& v, const Vec3& a);

/// The programme: one clamped uniform B-spline from the start state over a
/// free duration T, its end on the finish plane; the cost is the time from
/// its first crossing of the start plane to T. Control points 0..2 follow
/// from the start state and T, the last one's x is the finish plane.
/// Variables: T / kTimeScale, then control points 3..n-1 relative to the
/// start / kLengthScale (x, y, z each; the last point y, z only).
class Programme {
 public:
  // Variable scales: the programme's variables are O(1..10) so that SLSQP's
  // unit initial Hessian is not far off.
  static constexpr double kLengthScale = 10.0;  // m
  static constexpr double kTimeScale = 10.0;    // s

  /// `intervals` B-spline intervals of `degree`; constraint samples every
  /// `sample_spacing` of `duration_guess` (8 to 800 of them); the run-up
  /// (start state to start plane) weighs `run_up_weight` in the cost
  /// (clamped to [0.001, 1]). The course must outlive the programme.
  Programme(const Course& course, int degree, int intervals, double duration_guess,
            double sample_spacing, double run_up_weight);

  int num_variables() const { return 3 * n_ - 9; }
  int num_constraints() const { return kRows * static_cast<int>(s_.size()); }
  int num_control_points() const { return n_; }
  const BsplineBasis& basis() const { return basis_; }

  /// Index of control point i's axis in z, -1 when it is fixed.
  int var_index(int i, int axis) const;

  double duration(const double* z) const { return kTimeScale * z[0]; }

  /// Control points and the derivatives of points 1 and 2 with respect to T.
  void control_points(const double* z, std::vector<Vec3>& p, Vec3& dp1, Vec3& dp2) const;

  /// Variables that put the control points at the Greville abscissae of a
  /// path sampled at constant speed (points 0..2 still from the start state).
  std::vector<double> fit(const std::function<Vec3(double)>& path_at_fraction,
                          double duration) const;

  /// First s where the curve's x reaches x_plane (x of the curve at 1 is the finish).
  double crossing(const std::vector<Vec3>& p, double x_plane) const;

  /// Gate-to-gate time / kTimeScale (the run-up weighted in) and its
  /// gradient (num_variables entries; none when grad is null).
  double objective(const double* z, double* grad) const;

  /// Normalised constraints (<= 0 met), rows kRows per sample, and their
  /// Jacobian (row-major, num_constraints x num_variables; none when jac is
  /// null).
  void constraints(const double* z, double* out, double* jac) const;

  BsplineTrajectory trajectory(const double* z) const;

 private:
  static Vec3 eval(const Eigen::RowVectorXd& row, const std::vector<Vec3>& p);

  const Course& course_;
  BsplineBasis basis_;
  double run_up_weight_;
  int n_ = 0;
  std::array<double, 2> r1_{};
  std::array<double, 3> r2_{};
  std::vector<double> s_;
  std::vector<std::array<Eigen::RowVectorXd, 3>> rows_;
};

}  // namespace ofn::baseline
