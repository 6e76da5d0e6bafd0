// Clamped uniform B-splines: the flat outputs of the RH optimiser and the
// trajectory REF_TRAJ carries.

#include <gtest/gtest.h>

#include <random>
#include <stdexcept>

#include "ofn/common/bspline.hpp"

namespace ofn {
namespace {

TEST(BsplineBasis, KnotsAreClampedAndUniform) {
  const BsplineBasis basis(5, 4);
  ASSERT_EQ(basis.num_control_points(), 9);
  const std::vector<double> expected{0, 0, 0, 0, 0, 0, 0.25, 0.5, 0.75, 1, 1, 1, 1, 1, 1};
  EXPECT_EQ(basis.knots(), expected);
}

TEST(BsplineBasis, RejectsBadDegreeOrIntervals) {
  EXPECT_THROW(BsplineBasis(0, 3), std::invalid_argument);
  EXPECT_THROW(BsplineBasis(8, 3), std::invalid_argument);
  EXPECT_THROW(BsplineBasis(3, 0), std::invalid_argument);
}

TEST(BsplineBasis, PartitionOfUnityAndNonNegative) {
  for (int degree = 1; degree <= 7; ++degree) {
    const BsplineBasis basis(degree, 6);
    for (int k = 0; k <= 200; ++k) {
      const double s = k / 200.0;
      const Eigen::RowVectorXd row = basis.evaluate(s, 0);
      EXPECT_NEAR(row.sum(), 1.0, 1e-12) << "degree " << degree << " s " << s;
      EXPECT_GE(row.minCoeff(), -1e-15);
      // Derivatives of a partition of unity sum to zero.
      for (int d = 1; d <= 3; ++d) EXPECT_NEAR(basis.evaluate(s, d).sum(), 0.0, 1e-8);
    }
  }
}

TEST(BsplineBasis, ClampedEndsInterpolateEndControlPoints) {
  const BsplineBasis basis(5, 6);
  const int n = basis.num_control_points();
  const Eigen::RowVectorXd first = basis.evaluate(0.0, 0);
  const Eigen::RowVectorXd last = basis.evaluate(1.0, 0);
  EXPECT_DOUBLE_EQ(first(0), 1.0);
  EXPECT_DOUBLE_EQ(last(n - 1), 1.0);
  EXPECT_NEAR(first.tail(n - 1).cwiseAbs().sum(), 0.0, 1e-15);
  EXPECT_NEAR(last.head(n - 1).cwiseAbs().sum(), 0.0, 1e-15);
  // Outside [0, 1] the basis is clamped to the ends.
  EXPECT_TRUE(basis.evaluate(-0.3, 0).isApprox(first));
  EXPECT_TRUE(basis.evaluate(1.7, 0).isApprox(last));
}

TEST(BsplineBasis, DerivativesMatchFiniteDifferences) {
  const BsplineBasis basis(5, 6);
  const double h = 1e-6;
  for (int k = 1; k < 40; ++k) {
    const double s = k / 40.0 + 0.0037;  // off the knots, where derivatives are smooth
    for (int d = 1; d <= 4; ++d) {
      const Eigen::RowVectorXd numeric =
          (basis.evaluate(s + h, d - 1) - basis.evaluate(s - h, d - 1)) / (2 * h);
      const Eigen::RowVectorXd analytic = basis.evaluate(s, d);
      const double scale = std::max(1.0, analytic.cwiseAbs().maxCoeff());
      EXPECT_LT((numeric - analytic).cwiseAbs().maxCoeff(), 1e-5 * scale)
          << "s " << s << " derivative " << d;
    }
  }
}

TEST(BsplineBasis, DerivativeBeyondDegreeIsZero) {
  const BsplineBasis basis(3, 4);
  EXPECT_NEAR(basis.evaluate(0.4, 4).cwiseAbs().sum(), 0.0, 1e-12);
}

std::vector<Vec3> random_points(int count, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-20.0, 20.0);
  std::vector<Vec3> points;
  for (int i = 0; i < count; ++i) points.emplace_back(u(rng), u(rng), u(rng));
  return points;
}

TEST(BsplineTrajectory, MatchesBasisTimesControlPointsWithDurationScaling) {
  const BsplineBasis basis(5, 6);
  const std::vector<Vec3> points = random_points(basis.num_control_points(), 3);
  const double duration = 7.5;
  const BsplineTrajectory trajectory(5, basis.knots(), points, duration);
  for (int k = 0; k <= 30; ++k) {
    const double t = duration * k / 30.0;
    for (int d = 0; d <= 3; ++d) {
      const Eigen::RowVectorXd row = basis.evaluate(t / duration, d);
      Vec3 expected = Vec3::Zero();
      for (int j = 0; j < row.size(); ++j) expected += row(j) * points[static_cast<size_t>(j)];
      expected /= std::pow(duration, d);
      EXPECT_LT((trajectory.evaluate(t, d) - expected).norm(), 1e-9 * (1 + expected.norm()))
          << "t " << t << " derivative " << d;
    }
  }
}

TEST(BsplineTrajectory, VelocityAndAccelerationAreTimeDerivatives) {
  const BsplineBasis basis(5, 6);
  const BsplineTrajectory trajectory(5, basis.knots(), random_points(11, 9), 12.0);
  const double h = 1e-5;
  for (double t = 0.3; t < 12.0; t += 0.77) {
    const Vec3 velocity = (trajectory.position(t + h) - trajectory.position(t - h)) / (2 * h);
    const Vec3 accel = (trajectory.velocity(t + h) - trajectory.velocity(t - h)) / (2 * h);
    const Vec3 jerk = (trajectory.acceleration(t + h) - trajectory.acceleration(t - h)) / (2 * h);
    EXPECT_LT((velocity - trajectory.velocity(t)).norm(), 1e-6 * (1 + velocity.norm()));
    EXPECT_LT((accel - trajectory.acceleration(t)).norm(), 1e-6 * (1 + accel.norm()));
    EXPECT_LT((jerk - trajectory.evaluate(t, 3)).norm(), 1e-5 * (1 + jerk.norm()));
  }
}

TEST(BsplineTrajectory, SameShapeTwiceAsLongHasHalfTheVelocityAndQuarterTheAcceleration) {
  const BsplineBasis basis(5, 6);
  const std::vector<Vec3> points = random_points(11, 5);
  const BsplineTrajectory fast(5, basis.knots(), points, 4.0);
  const BsplineTrajectory slow(5, basis.knots(), points, 8.0);
  for (double s = 0; s <= 1.0; s += 0.1) {
    EXPECT_LT((slow.position(8.0 * s) - fast.position(4.0 * s)).norm(), 1e-9);
    EXPECT_LT((2.0 * slow.velocity(8.0 * s) - fast.velocity(4.0 * s)).norm(), 1e-9);
    EXPECT_LT((4.0 * slow.acceleration(8.0 * s) - fast.acceleration(4.0 * s)).norm(), 1e-9);
    EXPECT_LT((8.0 * slow.evaluate(8.0 * s, 3) - fast.evaluate(4.0 * s, 3)).norm(), 1e-8);
  }
}

TEST(BsplineTrajectory, EndsInterpolateAndHoldBeyondTheEnds) {
  const BsplineBasis basis(5, 6);
  const std::vector<Vec3> points = random_points(11, 7);
  const BsplineTrajectory trajectory(5, basis.knots(), points, 10.0);
  EXPECT_LT((trajectory.position(0) - points.front()).norm(), 1e-12);
  EXPECT_LT((trajectory.position(10.0) - points.back()).norm(), 1e-12);
  EXPECT_LT((trajectory.position(-5) - points.front()).norm(), 1e-12);
  EXPECT_LT((trajectory.position(25) - points.back()).norm(), 1e-12);
  EXPECT_LT((trajectory.velocity(25) - trajectory.velocity(10.0)).norm(), 1e-12);
  const std::vector<double> times = trajectory.knot_times();
  EXPECT_DOUBLE_EQ(times.back(), 10.0);
  EXPECT_NEAR(times[6], 10.0 / 6.0, 1e-12);
}

TEST(BsplineTrajectory, RejectsInconsistentSizes) {
  const BsplineBasis basis(5, 6);
  EXPECT_THROW(BsplineTrajectory(5, basis.knots(), random_points(10, 1), 3.0),
               std::invalid_argument);
  EXPECT_THROW(BsplineTrajectory(5, basis.knots(), random_points(11, 1), 0.0),
               std::invalid_argument);
  EXPECT_TRUE(BsplineTrajectory().empty());
}

TEST(BsplineTrajectory, NonUniformKnotsOfLowDegree) {
  // A quadratic with one interior knot: a parabola then a constant, as the
  // braking trajectory uses.
  const Vec3 p0(0, 0, 0), stop(5, 0, 0);
  const BsplineTrajectory trajectory(2, {0, 0, 0, 0.25, 1, 1, 1}, {p0, stop, stop, stop}, 8.0);
  // The first piece spans t in [0, 2]: v(0) = 2 (stop - p0) / 2 = 5 m/s.
  EXPECT_NEAR(trajectory.velocity(0).x(), 5.0, 1e-12);
  EXPECT_NEAR(trajectory.acceleration(1.0).x(), -2.5, 1e-12);
  EXPECT_NEAR(trajectory.position(2.0).x(), 5.0, 1e-12);
  EXPECT_NEAR(trajectory.velocity(5.0).norm(), 0.0, 1e-12);
}

}  // namespace
}  // namespace ofn
