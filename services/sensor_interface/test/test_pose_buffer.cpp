// PoseBuffer: the pose of each LIDAR beam's firing time from the NAV_STATE
// history, between samples, a little past the newest, and never outside.

#include <gtest/gtest.h>

#include <cmath>

#include "ofn/sensor_interface/pose_buffer.hpp"

namespace ofn::sensing {
namespace {

constexpr Utime kNavPeriod = 10000;  // 100 Hz

Pose pose_at(Utime t, const Vec3& p0, const Vec3& v, double yaw0, double yaw_rate) {
  Pose p;
  p.utime = t;
  p.position = p0 + v * to_seconds(t);
  p.velocity = v;
  p.attitude = quat_from_euler(0.05, -0.1, yaw0 + yaw_rate * to_seconds(t));
  return p;
}

TEST(PoseBuffer, InterpolatesLinearMotionExactly) {
  PoseBuffer buffer;
  const Vec3 p0(10, -5, -30), v(4.0, -1.5, 0.5);
  for (Utime t = 0; t <= 10 * kNavPeriod; t += kNavPeriod)
    ASSERT_TRUE(buffer.insert(pose_at(t, p0, v, 0.3, 0.0)));
  for (Utime t : {Utime{0}, Utime{13700}, Utime{45001}, Utime{99999}, 10 * kNavPeriod}) {
    const auto pose = buffer.interpolate(t);
    ASSERT_TRUE(pose) << t;
    EXPECT_EQ(pose->utime, t);
    EXPECT_LT((pose->position - (p0 + v * to_seconds(t))).norm(), 1e-9) << t;
    EXPECT_LT((pose->velocity - v).norm(), 1e-9);
  }
}

TEST(PoseBuffer, InterpolatesConstantYawRateExactly) {
  PoseBuffer buffer;
  const double yaw_rate = 0.8;  // rad/s: 8 mrad between samples
  for (Utime t = 0; t <= 50 * kNavPeriod; t += kNavPeriod)
    ASSERT_TRUE(buffer.insert(pose_at(t, Vec3::Zero(), Vec3::Zero(), 3.0, yaw_rate)));
  // Crosses +-pi on the way: the shorter rotation must be taken.
  for (Utime t = 1234; t < 50 * kNavPeriod; t += 7919) {
    const auto pose = buffer.interpolate(t);
    ASSERT_TRUE(pose) << t;
    const Quat expected = pose_at(t, Vec3::Zero(), Vec3::Zero(), 3.0, yaw_rate).attitude;
    EXPECT_LT(pose->attitude.angularDistance(expected), 1e-9) << t;
  }
}

TEST(PoseBuffer, RejectsOutOfOrderAndDuplicateSamples) {
  PoseBuffer buffer;
  ASSERT_TRUE(buffer.insert(pose_at(20000, Vec3::Zero(), Vec3(1, 0, 0), 0, 0)));
  Pose older = pose_at(10000, Vec3(100, 0, 0), Vec3::Zero(), 0, 0);
  EXPECT_FALSE(buffer.insert(older));
  Pose duplicate = pose_at(20000, Vec3(100, 0, 0), Vec3::Zero(), 0, 0);
  EXPECT_FALSE(buffer.insert(duplicate));
  EXPECT_EQ(buffer.size(), 1u);
  EXPECT_EQ(buffer.newest()->utime, 20000);
  EXPECT_NEAR(buffer.newest()->position.x(), 0.02, 1e-12);  // the rejected ones left no trace
  EXPECT_TRUE(buffer.insert(pose_at(30000, Vec3::Zero(), Vec3(1, 0, 0), 0, 0)));
  EXPECT_EQ(buffer.size(), 2u);
}

TEST(PoseBuffer, ExtrapolatesOnlyUpToTheLimit) {
  PoseBuffer buffer(2.0, 0.03);
  const Vec3 v(2.0, 0, -1.0);
  buffer.insert(pose_at(1000000, Vec3::Zero(), v, 0.0, 0.5));
  buffer.insert(pose_at(1010000, Vec3::Zero(), v, 0.0, 0.5));
  const Pose newest = *buffer.newest();

  const auto ahead = buffer.interpolate(1030000);  // 20 ms past the newest
  ASSERT_TRUE(ahead);
  EXPECT_LT((ahead->position - (newest.position + v * 0.02)).norm(), 1e-9);
  EXPECT_LT(ahead->attitude.angularDistance(newest.attitude), 1e-12);
  EXPECT_TRUE(buffer.interpolate(1040000));   // exactly at the limit
  EXPECT_FALSE(buffer.interpolate(1040001));  // beyond it
  EXPECT_FALSE(buffer.interpolate(999999));   // before the oldest: never guessed
}

TEST(PoseBuffer, NoExtrapolationWhenTheLimitIsZero) {
  PoseBuffer buffer(2.0, 0.0);
  buffer.insert(pose_at(0, Vec3::Zero(), Vec3(1, 0, 0), 0, 0));
  EXPECT_TRUE(buffer.interpolate(0));
  EXPECT_FALSE(buffer.interpolate(1));
  EXPECT_FALSE(PoseBuffer().interpolate(0));  // empty
}

TEST(PoseBuffer, KeepsTheConfiguredHistoryAndNoMore) {
  PoseBuffer buffer(2.0, 0.03);
  const Vec3 v(3, 0, 0);
  for (Utime t = 0; t <= 5 * kMicrosPerSecond; t += kNavPeriod)
    ASSERT_TRUE(buffer.insert(pose_at(t, Vec3::Zero(), v, 0, 0)));
  const Utime newest = buffer.newest()->utime;
  ASSERT_EQ(newest, 5 * kMicrosPerSecond);
  // The whole history is still there ...
  const auto edge = buffer.interpolate(newest - 2 * kMicrosPerSecond);
  ASSERT_TRUE(edge);
  EXPECT_NEAR(edge->position.x(), 3.0 * 3.0, 1e-9);
  // ... and what is older is gone.
  EXPECT_GE(buffer.oldest()->utime, newest - 2 * kMicrosPerSecond - kNavPeriod);
  EXPECT_FALSE(buffer.interpolate(newest - 2 * kMicrosPerSecond - kNavPeriod - 1));
  EXPECT_LE(buffer.size(), 202u);
}

}  // namespace
}  // namespace ofn::sensing
