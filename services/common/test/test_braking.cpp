// The stop of braking.hpp: what the commit gate checks and what the
// controller flies when the plans stop coming.

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "ofn/common/braking.hpp"

namespace ofn {
namespace {

constexpr double kDecel = 0.39;  // m/s^2: 0.8 of the benchmarks' 1.6 ft/s^2

// Velocity and acceleration are the position's derivatives; the state is
// continuous; the stop never turns and ends at rest on its stop point.
void expect_consistent(const StopProfile& stop, const std::string& label) {
  const double h = 1e-5;
  const Vec3 along = stop.direction();
  for (int k = 1; k <= 400; ++k) {  // from after the start, where the state is held
    const double t = (stop.stop_time + 2.0) * k / 400.0;
    const Vec3 v = stop.velocity_at(t), a = stop.acceleration_at(t);
    const Vec3 dp = (stop.position(t + h) - stop.position(t - h)) / (2 * h);
    const Vec3 dv = (stop.velocity_at(t + h) - stop.velocity_at(t - h)) / (2 * h);
    EXPECT_LT((dp - v).norm(), 1e-6) << label << ", t " << t;
    EXPECT_LT((dv - a).norm(), 1e-4) << label << ", t " << t;
    EXPECT_LE(a.norm(), stop.deceleration + 1e-12) << label << ", t " << t;
    EXPECT_GE(v.dot(along), 0.0) << label << ", t " << t;
  }
  // No step in acceleration anywhere, the hover included.
  for (double t : {stop.onset_time, stop.onset_time + stop.constant_time, stop.stop_time}) {
    if (t <= 1e-6) continue;  // the start, not a join
    EXPECT_LT((stop.acceleration_at(t - 1e-7) - stop.acceleration_at(t + 1e-7)).norm(), 1e-5)
        << label << ", t " << t;
  }
  EXPECT_LT(stop.velocity_at(stop.stop_time).norm(), 1e-12) << label;
  EXPECT_LT((stop.position(stop.stop_time + 10) - stop.stop_point()).norm(), 1e-12) << label;
  EXPECT_LT((stop.stop_point() - (stop.start + along * stop.distance())).norm(), 1e-12) << label;
}

TEST(StopProfile, BuildsUpDeceleratesThenEasesOutToAHoverAlongTheVelocity) {
  const Vec3 start(5, -2, -30), velocity(2.0, -1.5, 0.5);
  const double onset = 0.5, ramp = 0.8;
  const StopProfile stop = stop_from(start, velocity, kDecel, ramp, onset);
  const double speed = velocity.norm();
  EXPECT_NEAR(stop.onset_time, onset, 1e-12);
  EXPECT_NEAR(stop.constant_time, speed / kDecel - 0.5 * (onset + ramp), 1e-12);
  EXPECT_NEAR(stop.stop_time, speed / kDecel + 0.5 * (onset + ramp), 1e-12);
  // As if the deceleration stepped in half-way through the onset, less
  // a tau^2 / 24 for the onset's curve, plus a tau^2 / 24 for the ease-out's.
  EXPECT_NEAR(stop.distance(),
              speed * speed / (2 * kDecel) + 0.5 * speed * onset +
                  kDecel * (ramp * ramp - onset * onset) / 24,
              1e-12);
  EXPECT_LT(stop.acceleration_at(0).norm(), 1e-12);  // from not speeding up
  expect_consistent(stop, "from cruise");
  for (int k = 1; k < 100; ++k)
    EXPECT_LE(stop.velocity_at(stop.stop_time * k / 100).norm(), speed + 1e-12);
}

TEST(StopProfile, FromAReferenceSpeedingUpItBuildsUpFromThatAcceleration) {
  // The reference was still speeding up along the velocity (and turning,
  // which the straight stop leaves out): the stop starts from that
  // acceleration and turns it into the deceleration at the same jerk.
  const Vec3 velocity(0.45, 0, 0), acceleration(0.3, 0.2, 0);
  const double onset = 0.6, ramp = 2.4;
  const StopProfile stop = stop_from(Vec3::Zero(), velocity, acceleration, kDecel, ramp, onset);
  EXPECT_NEAR(stop.start_acceleration, 0.3, 1e-12);
  EXPECT_NEAR(stop.acceleration_at(0).x(), 0.3, 1e-12);
  EXPECT_NEAR((0.3 + stop.peak_deceleration) / stop.onset_time, kDecel / onset, 1e-9);
  EXPECT_NEAR(stop.peak_deceleration / stop.ramp_time, kDecel / ramp, 1e-9);
  EXPECT_GT(stop.distance(), stop_from(Vec3::Zero(), velocity, kDecel, ramp, onset).distance());
  expect_consistent(stop, "speeding up");
  // Braking already, beyond the deceleration: from the deceleration.
  const StopProfile braking =
      stop_from(Vec3::Zero(), Vec3(3, 0, 0), Vec3(-1.0, 0, 0), kDecel, ramp, onset);
  EXPECT_NEAR(braking.start_acceleration, -kDecel, 1e-12);
  EXPECT_NEAR(braking.onset_time, 0.0, 1e-12);
  expect_consistent(braking, "braking hard");
}

TEST(StopProfile, ASlowStopHasNoConstantPartAndTheSameJerks) {
  const double onset = 0.6, ramp = 0.8, speed = 0.05;
  const StopProfile stop = stop_from(Vec3::Zero(), Vec3(0, speed, 0), kDecel, ramp, onset);
  EXPECT_EQ(stop.constant_time, 0.0);
  EXPECT_LT(stop.peak_deceleration, kDecel);
  EXPECT_NEAR(stop.peak_deceleration / stop.ramp_time, kDecel / ramp, 1e-9);
  EXPECT_NEAR(stop.peak_deceleration / stop.onset_time, kDecel / onset, 1e-9);
  expect_consistent(stop, "slow");
  // Without an onset: all ease-out, quadratic to rest.
  const StopProfile quick = stop_from(Vec3::Zero(), Vec3(0, speed, 0), kDecel, ramp, 0.0);
  EXPECT_NEAR(quick.acceleration_at(0).y(), -quick.peak_deceleration, 1e-12);
  EXPECT_NEAR(quick.speed_at(0.5 * quick.stop_time), speed / 4, 1e-12);
  // Slow and braking hard already: eased out from there, at once.
  const StopProfile hard =
      stop_from(Vec3::Zero(), Vec3(0, speed, 0), Vec3(0, -0.3, 0), kDecel, ramp, onset);
  EXPECT_NEAR(hard.acceleration_at(0).y(), -0.3, 1e-12);
  EXPECT_EQ(hard.onset_time, 0.0);
  EXPECT_EQ(hard.constant_time, 0.0);
  expect_consistent(hard, "slow, braking hard");
}

TEST(StopProfile, NoRampOrOnsetIsAStepToTheHoverAndAHoverHasNoStop) {
  const StopProfile step = stop_from(Vec3::Zero(), Vec3(3, 0, 0), kDecel, 0.0, 0.0);
  EXPECT_NEAR(step.stop_time, 3 / kDecel, 1e-12);
  EXPECT_NEAR(step.distance(), 9 / (2 * kDecel), 1e-12);
  EXPECT_NEAR(step.acceleration_at(0).x(), -kDecel, 1e-12);
  const StopProfile hover = stop_from(Vec3(1, 2, 3), Vec3::Zero(), kDecel);
  EXPECT_EQ(hover.stop_time, 0.0);
  EXPECT_LT((hover.position(5) - Vec3(1, 2, 3)).norm(), 1e-12);
  // Garbage deceleration brakes at 1 m/s^2 rather than not at all, and a
  // garbage acceleration counts as none.
  EXPECT_EQ(stop_from(Vec3::Zero(), Vec3(1, 0, 0), std::nan("")).deceleration, 1.0);
  const StopProfile garbage =
      stop_from(Vec3::Zero(), Vec3(1, 0, 0), Vec3(std::nan(""), 0, 0), kDecel);
  EXPECT_EQ(garbage.start_acceleration, 0.0);
  EXPECT_TRUE(std::isfinite(garbage.distance()));
}

}  // namespace
}  // namespace ofn
