#pragma once
// Clamped uniform B-splines: the flat outputs x(t), y(t), z(t) of the RH
// optimiser (paper 4.1) and the trajectory REF_TRAJ carries. The basis is
// built once on the normalised parameter s = t / T in [0, 1]; a trajectory of
// duration T scales the k-th derivative by 1 / T^k, which is what makes the
// free final time cheap to optimise.

#include <vector>

#include <Eigen/Dense>

#include "ofn/common/frames.hpp"

namespace ofn {

class BsplineBasis {
 public:
  /// Throws std::invalid_argument unless 1 <= degree <= 7 and intervals >= 1.
  BsplineBasis(int degree, int intervals);

  int degree() const { return degree_; }
  int intervals() const { return intervals_; }
  int num_control_points() const { return intervals_ + degree_; }
  /// Normalised clamped knots: degree + 1 zeros, the interior knots, degree + 1 ones.
  const std::vector<double>& knots() const { return knots_; }

  /// Basis values (derivative = 0) or their derivatives with respect to s,
  /// one per control point, at s in [0, 1] (clamped).
  Eigen::RowVectorXd evaluate(double s, int derivative) const;

 private:
  int degree_;
  int intervals_;
  std::vector<double> knots_;
};

/// A B-spline trajectory in world NED over t in [0, duration] (s from its
/// start time). Beyond the ends it holds the end values (derivatives too).
class BsplineTrajectory {
 public:
  BsplineTrajectory() = default;
  /// knots are normalised (as BsplineBasis::knots()); control points world NED.
  /// Throws std::invalid_argument if the sizes do not fit or duration <= 0.
  BsplineTrajectory(int degree, std::vector<double> normalised_knots,
                    std::vector<Vec3> control_points, double duration);

  bool empty() const { return control_points_.empty(); }
  int degree() const { return degree_; }
  double duration() const { return duration_; }
  const std::vector<double>& normalised_knots() const { return knots_; }
  /// Knots in seconds from the start (normalised knots * duration).
  std::vector<double> knot_times() const;
  const std::vector<Vec3>& control_points() const { return control_points_; }

  /// derivative 0: position, 1: velocity, 2: acceleration, 3: jerk.
  Vec3 evaluate(double t, int derivative) const;
  Vec3 position(double t) const { return evaluate(t, 0); }
  Vec3 velocity(double t) const { return evaluate(t, 1); }
  Vec3 acceleration(double t) const { return evaluate(t, 2); }

 private:
  int degree_ = 0;
  std::vector<double> knots_;
  std::vector<Vec3> control_points_;
  double duration_ = 0;
};

}  // namespace ofn
