// The speed reserve: nothing in calm flight, about one RMS of the velocity
// error in gusts, smooth in between, bounded, and robust to bad input.

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "ofn/controller/speed_reserve.hpp"

namespace ofn::control {
namespace {

constexpr double kStepPeriod = 0.01;
constexpr double kMaxSpeed = 3.048;  // m/s, 10 ft/s

/// Feeds `seconds` of a velocity error with the given RMS (Gaussian,
/// seeded) and returns the reserve.
double reserve_after(SpeedReserve& r, double rms, double seconds, unsigned seed = 1) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, rms / std::sqrt(3.0));
  for (int i = 0; i < static_cast<int>(seconds / kStepPeriod); ++i)
    r.update(Vec3(noise(rng), noise(rng), noise(rng)), kStepPeriod);
  return r.reserve(kMaxSpeed);
}

TEST(SpeedReserve, CalmFlightKeepsNothingBack) {
  SpeedReserve r;
  EXPECT_EQ(r.reserve(kMaxSpeed), 0.0);
  // The calmest and the roughest calm flights measured (0.04-0.15 m/s RMS).
  EXPECT_EQ(reserve_after(r, 0.05, 60.0), 0.0);
  EXPECT_EQ(reserve_after(r, 0.2, 60.0), 0.0);
  EXPECT_NEAR(r.rms(), 0.2, 0.03);
}

TEST(SpeedReserve, GustsKeepBackAFewRmsOfTheVelocityError) {
  SpeedReserve r;
  const double reserve = reserve_after(r, 0.6, 60.0);
  EXPECT_NEAR(r.rms(), 0.6, 0.05);
  EXPECT_NEAR(reserve, r.settings().sigmas * r.rms(), 1e-12);  // past `full`
  EXPECT_GT(reserve, r.rms());
}

TEST(SpeedReserve, GrowsSmoothlyAndMonotonicallyBetweenOnsetAndFull) {
  SpeedReserveSettings s;
  s.max_fraction = 0.9;  // not reached below 0.8 m/s RMS
  double previous = 0;
  double largest_step = 0;
  for (double sigma = 0.0; sigma <= 0.8; sigma += 0.001) {
    SpeedReserve r(s);
    // A constant error along one axis: the RMS is exactly its size.
    for (int i = 0; i < 20000; ++i) r.update(Vec3(sigma, 0, 0), 1.0);
    const double reserve = r.reserve(kMaxSpeed);
    EXPECT_GE(reserve, previous - 1e-12) << "at " << sigma;
    EXPECT_LE(reserve, sigma * s.sigmas + 1e-12);
    if (sigma <= s.onset) {
      EXPECT_EQ(reserve, 0.0);
    }
    if (sigma >= s.full) {
      EXPECT_NEAR(reserve, sigma * s.sigmas, 1e-9);
    }
    largest_step = std::max(largest_step, reserve - previous);
    previous = reserve;
  }
  // 1 mm/s of RMS never moves the reserve by more than a few mm/s.
  EXPECT_LT(largest_step, 0.005);
}

TEST(SpeedReserve, LearnsOfGustsOverItsTimeConstant) {
  SpeedReserve r;
  // From calm: after 1 s of a 0.6 m/s error the mean square is a tenth of
  // its value (1 - e^-0.1), short of the onset; after 3 time constants
  // 95 % of it.
  for (int i = 0; i < 100; ++i) r.update(Vec3(0.6, 0, 0), kStepPeriod);
  EXPECT_NEAR(r.rms(), 0.6 * std::sqrt(1.0 - std::exp(-0.1)), 1e-3);
  EXPECT_EQ(r.reserve(kMaxSpeed), 0.0);
  for (int i = 100; i < 3000; ++i) r.update(Vec3(0.6, 0, 0), kStepPeriod);
  EXPECT_NEAR(r.rms(), 0.6 * std::sqrt(1.0 - std::exp(-3.0)), 1e-3);
  EXPECT_NEAR(r.reserve(kMaxSpeed), r.settings().sigmas * r.rms(), 1e-9);
}

TEST(SpeedReserve, NeverTakesMoreThanItsShareOfTheLimit) {
  SpeedReserveSettings s;
  s.max_fraction = 0.3;
  SpeedReserve r(s);
  for (int i = 0; i < 5000; ++i) r.update(Vec3(5.0, 0, 0), kStepPeriod);
  EXPECT_NEAR(r.reserve(kMaxSpeed), 0.3 * kMaxSpeed, 1e-12);
  EXPECT_EQ(r.reserve(0.0), 0.0);  // no limit, nothing to keep back from
  EXPECT_EQ(r.reserve(-1.0), 0.0);
}

TEST(SpeedReserve, FollowsTheDisturbanceBackDownOverItsTimeConstant) {
  SpeedReserve r;
  EXPECT_GT(reserve_after(r, 0.7, 60.0), 0.7);
  // Five time constants of calm: the mean square falls by e^-5.
  EXPECT_EQ(reserve_after(r, 0.0, 5 * r.settings().time_constant), 0.0);
  EXPECT_LT(r.rms(), 0.7 * std::exp(-2.5) * 1.1);
}

TEST(SpeedReserve, IgnoresBadInputAndCanBeTurnedOff) {
  SpeedReserve r;
  reserve_after(r, 0.6, 60.0);
  const double before = r.rms();
  const double nan = std::nan("");
  r.update(Vec3(nan, 0, 0), kStepPeriod);
  r.update(Vec3(1, 0, 0), nan);
  r.update(Vec3(1, 0, 0), -1.0);
  r.update(Vec3(1, 0, 0), 0.0);
  EXPECT_EQ(r.rms(), before);
  r.reset();
  EXPECT_EQ(r.rms(), 0.0);

  SpeedReserveSettings off;
  off.enabled = false;
  SpeedReserve disabled(off);
  EXPECT_EQ(reserve_after(disabled, 1.0, 60.0), 0.0);
}

}  // namespace
}  // namespace ofn::control
