// The commanded heading: the path heading's bounded turn and hold, and the
// scanner's yaw sweep.

#include <gtest/gtest.h>

#include <cmath>
#include <optional>

#include "ofn/controller/heading_reference.hpp"

namespace ofn::control {
namespace {

constexpr double kDt = 0.01;

Vec3 direction(double yaw) {
  return Vec3(std::cos(yaw), std::sin(yaw), 0.0);
}

TEST(PathHeading, ARouteFlownBackTurnsAtTheBoundedRateNotAtOnce) {
  PathHeading settings;
  settings.max_rate = deg2rad(30);
  PathHeadingFilter heading(settings);
  heading.reset(0.0);
  // Facing straight back: the heading must take 6 s, never step.
  double previous = heading.yaw();
  double seconds = 0;
  while (std::abs(wrap_angle(heading.yaw() - kPi)) > 1e-9 && seconds < 20) {
    heading.update(direction(kPi), kDt);
    EXPECT_LE(std::abs(wrap_angle(heading.yaw() - previous)), settings.max_rate * kDt + 1e-12);
    previous = heading.yaw();
    seconds += kDt;
  }
  EXPECT_NEAR(seconds, kPi / settings.max_rate, 2 * kDt);
}

TEST(PathHeading, TurnsTheShortWayAcrossPlusMinusPi) {
  PathHeadingFilter heading(PathHeading{deg2rad(30), 1.0});
  heading.reset(deg2rad(170));
  for (int i = 0; i < 100; ++i) heading.update(direction(deg2rad(-170)), kDt);
  // 20 deg the short way takes 0.67 s; the long way would still be at 140 deg.
  EXPECT_NEAR(wrap_angle(heading.yaw() - deg2rad(-170)), 0.0, 1e-9);
}

// A look-around: always a quarter turn to the right of the heading, so the
// filtered heading turns one way at its bounded rate, through a full turn
// in 2 pi / max_rate.
TEST(PathHeading, ALookAroundTurnsAtTheBoundedRateThroughAFullTurn) {
  PathHeadingFilter filter;
  filter.reset(0.3);
  const double rate = PathHeading{}.max_rate;
  double turned = 0, last = filter.yaw();
  const int steps = static_cast<int>(std::ceil(2 * M_PI / rate / kDt));
  for (int i = 0; i < steps; ++i) {
    filter.update(look_around_facing(filter.yaw()), kDt);
    const double step = wrap_angle(filter.yaw() - last);
    EXPECT_NEAR(step, rate * kDt, 1e-9);
    turned += step;
    last = filter.yaw();
  }
  EXPECT_GE(turned, 2 * M_PI - 1e-9);
  EXPECT_NEAR(look_around_facing(0.0).y(), 1.0, 1e-12);  // east of north: to the right
}

TEST(PathHeading, HoldsWithNothingToFace) {
  PathHeadingFilter heading;
  EXPECT_FALSE(heading.initialised());
  heading.reset(0.4);
  EXPECT_TRUE(heading.initialised());
  for (int i = 0; i < 100; ++i) EXPECT_DOUBLE_EQ(heading.update(std::nullopt, kDt), 0.4);
}

TEST(PathHeading, NothingToFaceAlongAVerticalLegOrASlowReference) {
  EXPECT_FALSE(facing_along(Vec3(0.1, 0.0, -0.995), kMinLegHorizontal));  // climbing leg
  EXPECT_TRUE(facing_along(Vec3(0.6, 0.0, -0.8), kMinLegHorizontal));
  EXPECT_FALSE(facing_along(Vec3(0.5, 0.5, 0.0), 1.0));  // 0.7 m/s, below min_speed
  const auto fast = facing_along(Vec3(3.0, -4.0, 0.0), 1.0);
  ASSERT_TRUE(fast);
  EXPECT_EQ(*fast, Vec3(3.0, -4.0, 0.0));
}

TEST(PathHeading, FacesWhereThePlanIsGoingNotOnlyWhereItGoesNow) {
  // Flying north, the plan turns east: the direction faced already leans
  // into the turn.
  const Vec3 here(0, 0, -30), velocity(3, 0, 0), ahead(8, 4, -30);
  const auto facing = facing_ahead(here, velocity, ahead, 1.0);
  ASSERT_TRUE(facing);
  EXPECT_NEAR(std::atan2(facing->y(), facing->x()), std::atan2(4.0, 8.0), 1e-12);
  // Without a point ahead (a plan that ends now), along the velocity.
  const auto along = facing_ahead(here, velocity, std::nullopt, 1.0);
  ASSERT_TRUE(along);
  EXPECT_EQ(*along, velocity);
  // A point ahead less than a metre away points nowhere useful.
  EXPECT_EQ(*facing_ahead(here, velocity, Vec3(0.5, 0.5, -30), 1.0), velocity);
  // Slow: the heading holds, wherever the plan goes.
  EXPECT_FALSE(facing_ahead(here, Vec3(0.5, 0, 0), ahead, 1.0));
}

TEST(YawSweepOffset, StartsAtRestAndReachesTheFullSweepAfterOnePeriod) {
  YawSweep sweep;
  sweep.frequency = 0.2;
  sweep.total_angle = deg2rad(40);
  double rate = 1.0;
  EXPECT_DOUBLE_EQ(yaw_sweep_offset(sweep, 0.0, &rate), 0.0);
  EXPECT_DOUBLE_EQ(rate, 0.0);
  // After the ramp, the peaks are at +-half the total angle.
  double largest = 0;
  for (double t = 5.0; t < 15.0; t += kDt)
    largest = std::max(largest, std::abs(yaw_sweep_offset(sweep, t, &rate)));
  EXPECT_NEAR(largest, deg2rad(20), 1e-4);
  // The rate is the derivative of the offset.
  for (double t : {0.7, 3.1, 6.2, 9.9}) {
    const double h = 1e-6;
    double unused = 0;
    const double numeric =
        (yaw_sweep_offset(sweep, t + h, &unused) - yaw_sweep_offset(sweep, t - h, &unused)) /
        (2 * h);
    yaw_sweep_offset(sweep, t, &rate);
    EXPECT_NEAR(rate, numeric, 1e-6) << "t = " << t;
  }
}

}  // namespace
}  // namespace ofn::control
