// The controller service: the sampling of a REF_TRAJ.

#include <gtest/gtest.h>

#include "ofn/common/validate/ref_traj.hpp"
#include "ofn/controller/controller_service.hpp"
#include "ofn/ref_traj_t.hpp"

namespace ofn {
namespace {

ref_traj_t three_sample_traj(Utime t0) {
  ref_traj_t m{};
  m.utime = t0;
  m.t0_utime = t0;
  m.frame = "NED";
  m.sample_time = {0.0, 1.0, 2.0};
  m.position = {{0, 0, -30}, {10, 0, -30}, {10, 10, -20}};
  m.velocity = {{10, 0, 0}, {10, 0, 0}, {0, 10, 10}};
  m.acceleration = {{0, 0, 0}, {2, 0, 0}, {0, 0, 0}};
  m.num_samples = 3;
  return m;
}

TEST(SampleRefTraj, InterpolatesLinearlyBetweenSamples) {
  const Utime t0 = 5 * kMicrosPerSecond;
  const ref_traj_t traj = three_sample_traj(t0);
  ASSERT_EQ(validate(traj), "");

  const auto mid1 = control::sample_ref_traj(traj, t0 + to_utime(0.5));
  ASSERT_TRUE(mid1.has_value());
  EXPECT_NEAR((mid1->position - Vec3(5, 0, -30)).norm(), 0.0, 1e-9);
  EXPECT_NEAR((mid1->velocity - Vec3(10, 0, 0)).norm(), 0.0, 1e-9);
  EXPECT_NEAR((mid1->acceleration - Vec3(1, 0, 0)).norm(), 0.0, 1e-9);

  const auto mid2 = control::sample_ref_traj(traj, t0 + to_utime(1.25));
  ASSERT_TRUE(mid2.has_value());
  EXPECT_NEAR((mid2->position - Vec3(10, 2.5, -27.5)).norm(), 0.0, 1e-9);
  EXPECT_NEAR((mid2->velocity - Vec3(7.5, 2.5, 2.5)).norm(), 0.0, 1e-9);

  // The sample instants themselves, including both ends.
  for (int i = 0; i < 3; ++i) {
    const auto r = control::sample_ref_traj(traj, t0 + to_utime(i));
    ASSERT_TRUE(r.has_value()) << i;
    const auto& p = traj.position[i];
    EXPECT_NEAR((r->position - Vec3(p[0], p[1], p[2])).norm(), 0.0, 1e-9) << i;
  }
  // Time is measured from t0, not from zero.
  ref_traj_t late = three_sample_traj(0);
  late.t0_utime = 100 * kMicrosPerSecond;
  const auto r = control::sample_ref_traj(late, late.t0_utime + to_utime(0.5));
  ASSERT_TRUE(r.has_value());
  EXPECT_NEAR(r->position.x(), 5.0, 1e-9);
}

TEST(SampleRefTraj, OutsideTheSampledSpanIsNothing) {
  const Utime t0 = 5 * kMicrosPerSecond;
  const ref_traj_t traj = three_sample_traj(t0);
  EXPECT_FALSE(control::sample_ref_traj(traj, t0 - 1).has_value());
  EXPECT_FALSE(control::sample_ref_traj(traj, t0 - to_utime(1.0)).has_value());
  EXPECT_FALSE(control::sample_ref_traj(traj, t0 + to_utime(2.0) + 1).has_value());
  EXPECT_FALSE(control::sample_ref_traj(traj, t0 + to_utime(10.0)).has_value());
}

TEST(SampleRefTraj, SampleTimesAreRelativeToT0) {
  ref_traj_t traj = three_sample_traj(0);
  traj.t0_utime = 100 * kMicrosPerSecond;
  EXPECT_FALSE(control::sample_ref_traj(traj, to_utime(0.5)).has_value());
  EXPECT_FALSE(control::sample_ref_traj(traj, traj.t0_utime - 1).has_value());
  EXPECT_TRUE(control::sample_ref_traj(traj, traj.t0_utime).has_value());
  EXPECT_TRUE(control::sample_ref_traj(traj, traj.t0_utime + to_utime(2.0)).has_value());
}

}  // namespace
}  // namespace ofn
