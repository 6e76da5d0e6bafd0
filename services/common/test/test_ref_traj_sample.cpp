// A REF_TRAJ sent as its B-spline alone: it fits one datagram, validates,
// and every receiver samples it to the table the optimiser used to send.

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "ofn/common/bspline.hpp"
#include "ofn/common/ref_traj_sample.hpp"
#include "ofn/common/validate.hpp"

namespace ofn {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// A plan of the RH optimiser's shape: degree 5, 6 intervals, 20 s, climbing
// over something and turning.
BsplineTrajectory plan() {
  const BsplineBasis basis(5, 6);
  std::vector<Vec3> points;
  for (int i = 0; i < basis.num_control_points(); ++i)
    points.emplace_back(10.0 * i, 2.0 * std::sin(0.7 * i), -30.0 - 1.5 * i * (i < 6 ? 1 : 0));
  return BsplineTrajectory(basis.degree(), basis.knots(), points, 20.0);
}

ref_traj_t spline_only(const BsplineTrajectory& spline) {
  ref_traj_t m{};
  m.utime = 1000;
  m.t0_utime = 1000;
  m.frame = "NED";
  m.mode = ref_traj_t::AVOIDANCE;
  m.degree = spline.degree();
  m.knots = spline.knot_times();
  m.num_knots = static_cast<int32_t>(m.knots.size());
  for (const auto& p : spline.control_points()) m.control_points.push_back({p.x(), p.y(), p.z()});
  m.num_control_points = static_cast<int32_t>(m.control_points.size());
  m.num_samples = 0;
  return m;
}

TEST(RefTrajSpline, APlanAsItsSplineIsOneDatagramAndValid) {
  const ref_traj_t m = spline_only(plan());
  EXPECT_EQ(validate(m), "");
  // LCM sends up to 1435 bytes (channel name and header included) whole.
  EXPECT_LT(m.getEncodedSize() + 64, 1435);
  ref_traj_t sampled = m;
  set_ref_traj_samples(sampled, plan(), kRefTrajSamplePeriod);
  EXPECT_GT(sampled.getEncodedSize(), 10 * 1423);  // what it was with samples
}

TEST(RefTrajSpline, ReceiversSampleItAsTheSenderWould) {
  const BsplineTrajectory spline = plan();
  ref_traj_t sent = spline_only(spline);
  ref_traj_t with_samples = sent;
  set_ref_traj_samples(with_samples, spline, kRefTrajSamplePeriod);
  expand_ref_traj(sent);
  ASSERT_EQ(sent.num_samples, with_samples.num_samples);
  ASSERT_EQ(sent.num_samples, 201);  // 0, 0.1, ..., 20 s
  EXPECT_DOUBLE_EQ(sent.sample_time.back(), 20.0);
  for (size_t i = 0; i < sent.sample_time.size(); ++i) {
    EXPECT_NEAR(sent.sample_time[i], with_samples.sample_time[i], 1e-12);
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(sent.position[i][k], with_samples.position[i][k], 1e-9) << i;
      EXPECT_NEAR(sent.velocity[i][k], with_samples.velocity[i][k], 1e-9) << i;
      EXPECT_NEAR(sent.acceleration[i][k], with_samples.acceleration[i][k], 1e-9) << i;
    }
  }
  EXPECT_EQ(validate(sent), "");
  // And the state at any time is the spline's, to the interpolation.
  const auto mid = sample_ref_traj_at(sent, 7.05);
  ASSERT_TRUE(mid.has_value());
  EXPECT_LT((mid->position - spline.position(7.05)).norm(), 0.01);
  EXPECT_FALSE(sample_ref_traj_at(sent, 20.01).has_value());
}

TEST(RefTrajSpline, AMessageWithSamplesIsLeftAsItIs) {
  ref_traj_t m = spline_only(plan());
  set_ref_traj_samples(m, plan(), 0.5);
  const ref_traj_t before = m;
  expand_ref_traj(m);
  EXPECT_EQ(m.num_samples, before.num_samples);
  EXPECT_EQ(m.sample_time, before.sample_time);
  EXPECT_THROW(set_ref_traj_samples(m, plan(), 0.0), std::invalid_argument);
  EXPECT_THROW(set_ref_traj_samples(m, plan(), kNaN), std::invalid_argument);
}

TEST(RefTrajSpline, ABadSplineIsRejected) {
  const ref_traj_t good = spline_only(plan());
  auto rejected = [](ref_traj_t m) { return !validate(m).empty(); };
  ref_traj_t m = good;
  m.knots[2] = 0.5;  // not clamped at 0
  EXPECT_TRUE(rejected(m));
  m = good;
  m.knots[8] = m.knots[7] - 1.0;  // decreasing
  EXPECT_TRUE(rejected(m));
  m = good;
  m.knots[7] = kNaN;
  EXPECT_TRUE(rejected(m));
  m = good;
  m.control_points[3][1] = kNaN;
  EXPECT_TRUE(rejected(m));
  m = good;
  m.control_points[3][1] = 1e9;
  EXPECT_TRUE(rejected(m));
  m = good;
  m.degree = 0;
  EXPECT_TRUE(rejected(m));
  m = good;
  m.degree = 8;
  EXPECT_TRUE(rejected(m));
  m = good;
  m.control_points.pop_back();
  m.num_control_points -= 1;
  EXPECT_TRUE(rejected(m));  // knots no longer control points + degree + 1
  m = good;
  for (double& k : m.knots) k *= 1e4;  // 200,000 s: too many samples to make
  EXPECT_TRUE(rejected(m));
  m = good;
  m.control_points.clear();
  m.num_control_points = 0;
  EXPECT_TRUE(rejected(m));  // knots without control points, no samples
  m = good;
  m.knots.clear();
  m.num_knots = 0;
  m.control_points.clear();
  m.num_control_points = 0;
  EXPECT_TRUE(rejected(m));  // neither samples nor a spline
  m = good;
  m.num_knots = -1;
  EXPECT_TRUE(rejected(m));
}

}  // namespace
}  // namespace ofn
