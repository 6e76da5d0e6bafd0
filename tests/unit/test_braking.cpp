// The stop of braking.hpp: what the commit gate checks and what the
// controller flies when the plans stop coming.

#include <gtest/gtest.h>

#include <cmath>

#include "ofn/common/braking.hpp"

namespace ofn {
namespace {

constexpr double kDecel = 0.39;  // m/s^2: 0.8 of the benchmarks' 1.6 ft/s^2

TEST(StopProfile, DeceleratesThenEasesOutToAHoverAlongTheVelocity) {
  const Vec3 start(5, -2, -30), velocity(2.0, -1.5, 0.5);
  const StopProfile stop = stop_from(start, velocity, kDecel, 0.8);
  const double speed = velocity.norm();
  EXPECT_NEAR(stop.constant_time, speed / kDecel - 0.4, 1e-12);
  EXPECT_NEAR(stop.stop_time, speed / kDecel + 0.4, 1e-12);
  // The constant part's v^2 / (2 a) and a tau^2 / 24 for the ease-out.
  EXPECT_NEAR(stop.distance(), speed * speed / (2 * kDecel) + kDecel * 0.64 / 24, 1e-12);
  EXPECT_LT((stop.stop_point() - (start + velocity / speed * stop.distance())).norm(), 1e-12);
  // Continuous state; velocity and acceleration are the position's
  // derivatives; never faster, never turning, never above the deceleration.
  const double h = 1e-5;
  for (int k = 1; k <= 400; ++k) {  // from after the start, where the state is held
    const double t = (stop.stop_time + 2.0) * k / 400.0;
    const Vec3 v = stop.velocity_at(t), a = stop.acceleration_at(t);
    const Vec3 dp = (stop.position(t + h) - stop.position(t - h)) / (2 * h);
    const Vec3 dv = (stop.velocity_at(t + h) - stop.velocity_at(t - h)) / (2 * h);
    EXPECT_LT((dp - v).norm(), 1e-6) << "t " << t;
    if (std::abs(t - stop.constant_time) > 2 * h && std::abs(t - stop.stop_time) > 2 * h) {
      EXPECT_LT((dv - a).norm(), 1e-6) << "t " << t;
    }
    EXPECT_LE(a.norm(), kDecel + 1e-12);
    EXPECT_GE(v.dot(velocity), 0.0);
    EXPECT_LE(v.norm(), speed + 1e-12);
  }
  // The deceleration eases to zero: no step at the hover.
  EXPECT_LT(stop.acceleration_at(stop.stop_time - 1e-6).norm(), 1e-5);
  EXPECT_LT(stop.velocity_at(stop.stop_time).norm(), 1e-12);
  EXPECT_LT((stop.position(stop.stop_time + 10) - stop.stop_point()).norm(), 1e-12);
}

TEST(StopProfile, ASlowStopIsAllEaseOutAtTheSameJerk) {
  const double ramp = 0.8, speed = 0.05;  // below kDecel * ramp / 2
  const StopProfile stop = stop_from(Vec3::Zero(), Vec3(0, speed, 0), kDecel, ramp);
  EXPECT_EQ(stop.constant_time, 0.0);
  EXPECT_LT(stop.peak_deceleration, kDecel);
  EXPECT_NEAR(stop.peak_deceleration / stop.ramp_time, kDecel / ramp, 1e-12);
  EXPECT_NEAR(stop.acceleration_at(0).y(), -stop.peak_deceleration, 1e-12);
  EXPECT_LT(stop.velocity_at(stop.stop_time).norm(), 1e-12);
  EXPECT_NEAR(stop.speed_at(0.5 * stop.stop_time), speed / 4, 1e-12);  // quadratic to rest
}

TEST(StopProfile, NoRampIsAStepToTheHoverAndAHoverHasNoStop) {
  const StopProfile step = stop_from(Vec3::Zero(), Vec3(3, 0, 0), kDecel, 0.0);
  EXPECT_NEAR(step.stop_time, 3 / kDecel, 1e-12);
  EXPECT_NEAR(step.distance(), 9 / (2 * kDecel), 1e-12);
  const StopProfile hover = stop_from(Vec3(1, 2, 3), Vec3::Zero(), kDecel);
  EXPECT_EQ(hover.stop_time, 0.0);
  EXPECT_LT((hover.position(5) - Vec3(1, 2, 3)).norm(), 1e-12);
  // Garbage deceleration brakes at 1 m/s^2 rather than not at all.
  EXPECT_EQ(stop_from(Vec3::Zero(), Vec3(1, 0, 0), std::nan("")).deceleration, 1.0);
}

}  // namespace
}  // namespace ofn
