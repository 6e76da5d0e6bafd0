// The commanded heading: the path heading's bounded turn and hold, and the
// scanner's yaw sweep.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <optional>

#include "ofn/common/braking.hpp"
#include "ofn/controller/heading_reference.hpp"

namespace ofn::control {
namespace {

constexpr double kDt = 0.01;

Vec3 direction(double yaw) {
  return Vec3(std::cos(yaw), std::sin(yaw), 0.0);
}

TEST(PathHeading, ARouteFlownBackTurnsAtTheBoundedRateAndAccelerationNotAtOnce) {
  PathHeading settings;
  settings.max_rate = deg2rad(30);
  settings.max_accel = deg2rad(60);
  PathHeadingFilter heading(settings);
  heading.reset(0.0);
  // Facing straight back: the turn speeds up for 0.5 s, turns at 30 deg/s
  // and slows for 0.5 s: 6.5 s in all, never a step in angle or rate.
  double previous = heading.yaw(), previous_rate = 0;
  double seconds = 0, fastest = 0;
  while (std::abs(wrap_angle(heading.yaw() - kPi)) > 1e-9 && seconds < 20) {
    heading.update(direction(kPi), kDt);
    const double step = wrap_angle(heading.yaw() - previous);
    EXPECT_LE(std::abs(step), settings.max_rate * kDt + 1e-12);
    EXPECT_NEAR(heading.turn_rate(), step / kDt, 1e-9) << "the rate fed forward is the turn's";
    EXPECT_LE(std::abs(heading.turn_rate() - previous_rate), settings.max_accel * kDt + 1e-12);
    fastest = std::max(fastest, heading.turn_rate());
    previous = heading.yaw();
    previous_rate = heading.turn_rate();
    seconds += kDt;
  }
  EXPECT_NEAR(seconds, kPi / settings.max_rate + settings.max_rate / settings.max_accel, 3 * kDt);
  EXPECT_NEAR(fastest, settings.max_rate, 1e-12);
  EXPECT_LE(std::abs(heading.turn_rate()), settings.max_accel * kDt);  // the last step's
  // Settled: it stays on the direction.
  for (int i = 0; i < 100; ++i) heading.update(direction(kPi), kDt);
  EXPECT_NEAR(wrap_angle(heading.yaw() - kPi), 0.0, 1e-9);
  EXPECT_EQ(heading.turn_rate(), 0.0);
}

TEST(PathHeading, TurnsTheShortWayAcrossPlusMinusPi) {
  PathHeadingFilter heading(PathHeading{deg2rad(30), deg2rad(60), 1.0});
  heading.reset(deg2rad(170));
  for (int i = 0; i < 150; ++i) heading.update(direction(deg2rad(-170)), kDt);
  // 20 deg the short way takes 1.17 s; the long way would still be far off.
  EXPECT_NEAR(wrap_angle(heading.yaw() - deg2rad(-170)), 0.0, 1e-9);
}

TEST(PathHeading, WithNothingLeftToFaceTheTurnSlowsToAStop) {
  PathHeadingFilter heading(PathHeading{deg2rad(30), deg2rad(60), 1.0});
  heading.reset(0.0);
  for (int i = 0; i < 100; ++i) heading.update(direction(kPi / 2), kDt);
  ASSERT_NEAR(heading.turn_rate(), deg2rad(30), 1e-12);
  double previous_rate = heading.turn_rate();
  for (int i = 0; i < 100; ++i) {
    heading.update(std::nullopt, kDt);
    EXPECT_LE(std::abs(heading.turn_rate() - previous_rate), deg2rad(60) * kDt + 1e-12);
    previous_rate = heading.turn_rate();
  }
  EXPECT_EQ(heading.turn_rate(), 0.0);
  const double held = heading.yaw();
  heading.update(std::nullopt, kDt);
  EXPECT_EQ(heading.yaw(), held);
}

// A look-around: always a quarter turn to the right of the heading, so the
// filtered heading turns one way, speeding up to its bounded rate, through a
// full turn in max_rate / max_accel / 2 + 2 pi / max_rate.
TEST(PathHeading, ALookAroundTurnsAtTheBoundedRateThroughAFullTurn) {
  PathHeadingFilter filter;
  filter.reset(0.3);
  const PathHeading settings;
  const double rate = settings.max_rate;
  const double speeding_up = rate / settings.max_accel;
  double turned = 0, last = filter.yaw();
  const int steps = static_cast<int>(std::ceil((2 * M_PI / rate + 0.5 * speeding_up) / kDt));
  for (int i = 0; i < steps; ++i) {
    filter.update(look_around_facing(filter.yaw()), kDt);
    const double step = wrap_angle(filter.yaw() - last);
    if ((i + 1) * kDt > speeding_up + 1e-9) {
      EXPECT_NEAR(step, rate * kDt, 1e-9) << "at " << i;
    }
    EXPECT_NEAR(filter.turn_rate(), step / kDt, 1e-9);
    turned += step;
    last = filter.yaw();
  }
  EXPECT_GE(turned, 2 * M_PI - 1e-9);
  EXPECT_NEAR(look_around_facing(0.0).y(), 1.0, 1e-12);         // east of north: to the right
  EXPECT_NEAR(look_around_facing(0.0, true).y(), -1.0, 1e-12);  // to the left
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

/// Flies the sweep generator for `seconds` toward `half` (rad) and returns
/// the largest |offset| and |rate| over the last `window` seconds, checking
/// on the way that the rate is the offset's derivative.
struct SweepPeaks {
  double offset = 0;
  double rate = 0;
};
SweepPeaks fly_sweep(YawSweepGenerator& generator, double half, double seconds, double window) {
  SweepPeaks peaks;
  double previous = 0, previous_rate = 0;
  const int steps = static_cast<int>(std::lround(seconds / kDt));
  for (int k = 0; k < steps; ++k) {
    double rate = 0;
    const double offset = generator.update(half, kDt, &rate);
    // Trapezoidal integration of the rate follows the offset.
    if (k > 0) {
      EXPECT_NEAR(offset - previous, 0.5 * (rate + previous_rate) * kDt, 2e-5) << k;
    }
    previous = offset;
    previous_rate = rate;
    if ((k + 1) * kDt > seconds - window) {
      peaks.offset = std::max(peaks.offset, std::abs(offset));
      peaks.rate = std::max(peaks.rate, std::abs(rate));
    }
  }
  return peaks;
}

TEST(YawSweepGenerator, StartsAtRestAndReachesTheFullSweepAfterOnePeriod) {
  YawSweep sweep;
  sweep.frequency = 0.2;
  sweep.total_angle = deg2rad(40);
  YawSweepGenerator generator(sweep);
  double rate = 1.0;
  // The first step commands no offset and no rate.
  EXPECT_EQ(generator.update(deg2rad(20), kDt, &rate), 0.0);
  EXPECT_EQ(rate, 0.0);
  generator.restart();
  // After the ramp (one period), the peaks are at +-half the total angle,
  // at the nominal peak rate 2 pi f a.
  const SweepPeaks peaks = fly_sweep(generator, deg2rad(20), 15.0, 10.0);
  EXPECT_NEAR(peaks.offset, deg2rad(20), 1e-4);
  EXPECT_NEAR(peaks.rate, 2 * kPi * 0.2 * deg2rad(20), 1e-4);
  EXPECT_NEAR(generator.half_angle(), deg2rad(20), 1e-12);
}

TEST(YawSweepGenerator, WidensWhenAskedWithoutExceedingTheNominalPeakRate) {
  YawSweep sweep;  // +-20 deg at 0.2 Hz, up to +-60 deg
  YawSweepGenerator generator(sweep);
  fly_sweep(generator, deg2rad(20), 10.0, 0.0);
  const double nominal_rate = 2 * kPi * sweep.frequency * deg2rad(20);
  // Asked for +-60 deg: it widens at widen_rate, the peak rate stays.
  const SweepPeaks wide = fly_sweep(generator, deg2rad(60), 40.0, 15.0);
  EXPECT_NEAR(generator.half_angle(), deg2rad(60), 1e-6);
  EXPECT_NEAR(wide.offset, deg2rad(60), 2e-3);
  EXPECT_LE(wide.rate, nominal_rate * 1.001 + sweep.widen_rate);
  EXPECT_NEAR(wide.rate, nominal_rate, 1e-3);
  // Never wider than the wide limit, and back to nominal when asked.
  fly_sweep(generator, deg2rad(170), 20.0, 0.0);
  EXPECT_NEAR(generator.half_angle(), deg2rad(60), 1e-6);
  const SweepPeaks back = fly_sweep(generator, 0.0, 20.0, 10.0);
  EXPECT_NEAR(generator.half_angle(), deg2rad(20), 1e-6);
  EXPECT_NEAR(back.offset, deg2rad(20), 2e-3);
}

TEST(SweepHalfAngle, NominalWhileFacingWhereItGoesWideWhenSlower) {
  YawSweep sweep;  // +-20 deg, up to +-60 deg
  const SweepCoverage none;
  EXPECT_DOUBLE_EQ(sweep_half_angle(sweep, 3.048, 1.0, none), deg2rad(20));
  EXPECT_DOUBLE_EQ(sweep_half_angle(sweep, 1.0, 1.0, none), deg2rad(20));
  EXPECT_DOUBLE_EQ(sweep_half_angle(sweep, 0.99, 1.0, none), deg2rad(60));
  EXPECT_DOUBLE_EQ(sweep_half_angle(sweep, 0.0, 1.0, none), deg2rad(60));
  EXPECT_DOUBLE_EQ(sweep_half_angle(sweep, std::nan(""), 1.0, none), deg2rad(20));
  // Widening off: total_angle only.
  sweep.wide_total_angle = sweep.total_angle;
  EXPECT_DOUBLE_EQ(sweep_half_angle(sweep, 0.0, 1.0, none), deg2rad(20));
}

TEST(SweepHalfAngle, ReachesTheClearanceBesideThePathAtTheStoppingDistance) {
  YawSweep sweep;
  const SweepCoverage benchmarks{20 * 0.3048, 0.8 * 1.6 * 0.3048};  // R_s, 0.8 a_max
  // At cruise: the scan plane at the half angle reaches R_s to the side at
  // the stopping distance (12.0 m, the stop without its onset): +-27 deg,
  // not +-20.
  const double cruise = 3.048;
  const double stopping =
      stop_from(Vec3::Zero(), Vec3(cruise, 0, 0), benchmarks.deceleration, kStopRampTime, 0.0)
          .distance();
  const double half = sweep_half_angle(sweep, cruise, 1.0, benchmarks);
  EXPECT_NEAR(stopping * std::tan(half), benchmarks.clearance, 1e-9);
  EXPECT_NEAR(rad2deg(half), 26.9, 0.1);
  // Slower: a shorter stop, a wider sweep, up to cover_total_angle (below
  // the slow speed, the wide one).
  EXPECT_GT(sweep_half_angle(sweep, 2.9, 1.0, benchmarks), half);
  EXPECT_LT(sweep_half_angle(sweep, 2.9, 1.0, benchmarks), deg2rad(30));
  EXPECT_DOUBLE_EQ(sweep_half_angle(sweep, 2.0, 1.0, benchmarks), deg2rad(30));
  EXPECT_DOUBLE_EQ(sweep_half_angle(sweep, 1.0, 1.0, benchmarks), deg2rad(30));
  EXPECT_DOUBLE_EQ(sweep_half_angle(sweep, 0.9, 1.0, benchmarks), deg2rad(60));
  sweep.cover_total_angle = deg2rad(200);
  EXPECT_GT(sweep_half_angle(sweep, 2.0, 1.0, benchmarks), deg2rad(45));
  EXPECT_DOUBLE_EQ(sweep_half_angle(sweep, 1.0, 1.0, benchmarks), deg2rad(60));
  sweep.cover_total_angle = deg2rad(60);
  // Faster: never narrower than the nominal sweep.
  EXPECT_DOUBLE_EQ(sweep_half_angle(sweep, 10.0, 1.0, benchmarks), deg2rad(20));
  // The rule off, or nothing to cover: the nominal sweep.
  EXPECT_DOUBLE_EQ(sweep_half_angle(sweep, cruise, 1.0, SweepCoverage{}), deg2rad(20));
  EXPECT_DOUBLE_EQ(sweep_half_angle(sweep, cruise, 1.0, SweepCoverage{std::nan(""), 0.39}),
                   deg2rad(20));
  sweep.cover_clearance = false;
  EXPECT_DOUBLE_EQ(sweep_half_angle(sweep, cruise, 1.0, benchmarks), deg2rad(20));
}

}  // namespace
}  // namespace ofn::control
