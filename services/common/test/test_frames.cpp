// Frames and units: the conversions every service relies on at its edges.

#include <gtest/gtest.h>

#include <cmath>

#include "ofn/common/frames.hpp"

namespace ofn {
namespace {

TEST(Frames, EulerQuaternionRoundTripOverGrid) {
  int checked = 0;
  for (double roll_deg = -180; roll_deg <= 180; roll_deg += 15) {
    for (double pitch_deg = -80; pitch_deg <= 80; pitch_deg += 10) {
      for (double yaw_deg = -180; yaw_deg <= 180; yaw_deg += 15) {
        const double roll = deg2rad(roll_deg), pitch = deg2rad(pitch_deg), yaw = deg2rad(yaw_deg);
        const Quat q = quat_from_euler(roll, pitch, yaw);
        EXPECT_NEAR(q.norm(), 1.0, 1e-12);
        const Vec3 e = euler_from_quat(q);
        // Angles are compared modulo a full turn (+-180 deg name the same roll/yaw).
        EXPECT_NEAR(wrap_angle(e.x() - roll), 0.0, 1e-9)
            << "roll " << roll_deg << " pitch " << pitch_deg << " yaw " << yaw_deg;
        EXPECT_NEAR(e.y(), pitch, 1e-9)
            << "roll " << roll_deg << " pitch " << pitch_deg << " yaw " << yaw_deg;
        EXPECT_NEAR(wrap_angle(e.z() - yaw), 0.0, 1e-9)
            << "roll " << roll_deg << " pitch " << pitch_deg << " yaw " << yaw_deg;
        // And back: the same rotation (q and -q are the same rotation).
        const Quat q2 = quat_from_euler(e.x(), e.y(), e.z());
        EXPECT_NEAR(std::abs(q.dot(q2)), 1.0, 1e-12);
        ++checked;
      }
    }
  }
  EXPECT_EQ(checked, 25 * 17 * 25);
}

TEST(Frames, EulerConventionIsBodyToWorld321) {
  // Yaw 90 deg: body x (nose) points east in NED.
  const Vec3 nose = quat_from_euler(0, 0, deg2rad(90)) * Vec3::UnitX();
  EXPECT_NEAR(nose.x(), 0.0, 1e-12);
  EXPECT_NEAR(nose.y(), 1.0, 1e-12);
  // Positive pitch raises the nose: body x gets a negative (up) down component.
  const Vec3 pitched = quat_from_euler(0, deg2rad(30), 0) * Vec3::UnitX();
  EXPECT_LT(pitched.z(), 0.0);
  // Positive roll drops the right side: body y gets a positive down component.
  const Vec3 rolled = quat_from_euler(deg2rad(30), 0, 0) * Vec3::UnitY();
  EXPECT_GT(rolled.z(), 0.0);
}

TEST(Frames, EulerFromUnnormalisedQuaternionIsNormalisedFirst) {
  const Quat q = quat_from_euler(0.3, -0.2, 1.1);
  const Quat scaled(q.coeffs() * 3.0);
  const Vec3 e = euler_from_quat(scaled);
  EXPECT_NEAR(e.x(), 0.3, 1e-9);
  EXPECT_NEAR(e.y(), -0.2, 1e-9);
  EXPECT_NEAR(e.z(), 1.1, 1e-9);
}

TEST(Frames, CourseNedRoundTripAndHeightIsUp) {
  const Vec3 course(-100.0, 12.5, 120.0);
  const Vec3 ned = course_to_ned(course);
  EXPECT_DOUBLE_EQ(ned.x(), -100.0);
  EXPECT_DOUBLE_EQ(ned.y(), 12.5);
  EXPECT_DOUBLE_EQ(ned.z(), -120.0);  // height above ground is negative down
  const Vec3 back = ned_to_course(ned);
  EXPECT_TRUE(back.isApprox(course, 1e-15));
  for (double x : {-500.0, 0.0, 3.5})
    for (double y : {-7.0, 0.0, 42.0})
      for (double h : {0.0, 30.0, 1000.0}) {
        const Vec3 c(x, y, h);
        EXPECT_TRUE(ned_to_course(course_to_ned(c)).isApprox(c));
        EXPECT_TRUE(course_to_ned(ned_to_course(c)).isApprox(c));
      }
}

TEST(Frames, GuidanceFrameRoundTripAndLegEnd) {
  const Vec3 legs[][2] = {
      {Vec3(0, 0, -30), Vec3(100, 0, -30)},     // level north
      {Vec3(10, 20, -30), Vec3(-40, 70, -50)},  // descending to the north-west
      {Vec3(0, 0, 0), Vec3(0, 0, -25)},         // straight up
      {Vec3(5, 5, -10), Vec3(5, 5, 10)},        // straight down
      {Vec3(1, 2, 3), Vec3(4, -6, -8)},
  };
  for (const auto& leg : legs) {
    const auto g = GuidanceFrame::from_leg(leg[0], leg[1]);
    const double length = (leg[1] - leg[0]).norm();
    // Orthonormal, right-handed.
    EXPECT_TRUE((g.world_from_guidance.transpose() * g.world_from_guidance)
                    .isApprox(Mat3::Identity(), 1e-12));
    EXPECT_NEAR(g.world_from_guidance.determinant(), 1.0, 1e-12);
    // The leg start is the origin, the leg end lies on +x at the leg length.
    EXPECT_TRUE(g.to_guidance(leg[0]).isZero(1e-12));
    const Vec3 end = g.to_guidance(leg[1]);
    EXPECT_NEAR(end.x(), length, 1e-9);
    EXPECT_NEAR(end.y(), 0.0, 1e-9);
    EXPECT_NEAR(end.z(), 0.0, 1e-9);
    for (const Vec3& p : {Vec3(3, -4, 5), Vec3(-100, 250, -30), Vec3(0, 0, 0)}) {
      EXPECT_LT((g.to_world(g.to_guidance(p)) - p).norm(), 1e-9) << p.transpose();
      EXPECT_LT((g.to_guidance(g.to_world(p)) - p).norm(), 1e-9) << p.transpose();
      // Distances are preserved.
      EXPECT_NEAR(g.to_guidance(p).norm(), (p - leg[0]).norm(), 1e-9);
    }
  }
}

TEST(Frames, GuidanceFrameOfLevelLegHasYRightZDown) {
  const auto g = GuidanceFrame::from_leg(Vec3(0, 0, -30), Vec3(100, 0, -30));
  // Heading north: right is east, and z is down.
  EXPECT_TRUE(g.world_from_guidance.col(1).isApprox(Vec3::UnitY()));
  EXPECT_TRUE(g.world_from_guidance.col(2).isApprox(Vec3::UnitZ()));
  // A point 5 m east of the leg is 5 m to the right.
  EXPECT_NEAR(g.to_guidance(Vec3(50, 5, -30)).y(), 5.0, 1e-12);
}

TEST(Frames, GuidanceFrameOfDegenerateLegIsStillValid) {
  const auto g = GuidanceFrame::from_leg(Vec3(1, 1, 1), Vec3(1, 1, 1));
  EXPECT_TRUE(g.world_from_guidance.allFinite());
  EXPECT_NEAR(g.world_from_guidance.determinant(), 1.0, 1e-12);
}

TEST(Frames, WrapAngleRangeIsMinusPiExclusiveToPiInclusive) {
  for (double a = -50.0; a <= 50.0; a += 0.0137) {
    const double w = wrap_angle(a);
    EXPECT_GT(w, -kPi) << a;
    EXPECT_LE(w, kPi) << a;
    // Same direction: differs by a whole number of turns.
    const double turns = (a - w) / (2 * kPi);
    EXPECT_NEAR(turns, std::round(turns), 1e-9) << a;
  }
  EXPECT_NEAR(wrap_angle(kPi), kPi, 1e-12);
  EXPECT_NEAR(wrap_angle(-kPi), kPi, 1e-12);
  EXPECT_NEAR(wrap_angle(3 * kPi), kPi, 1e-9);
  EXPECT_NEAR(wrap_angle(0.0), 0.0, 1e-15);
  EXPECT_NEAR(wrap_angle(deg2rad(270)), deg2rad(-90), 1e-12);
  EXPECT_NEAR(wrap_angle(deg2rad(-190)), deg2rad(170), 1e-12);
}

TEST(Frames, UnitConversions) {
  EXPECT_NEAR(deg2rad(180.0), kPi, 1e-15);
  EXPECT_NEAR(rad2deg(kPi / 2), 90.0, 1e-12);
  EXPECT_DOUBLE_EQ(100.0 * kMetresPerFoot, 30.48);
}

}  // namespace
}  // namespace ofn
