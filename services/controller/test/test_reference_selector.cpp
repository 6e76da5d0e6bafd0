// The controller's reference selection: plan jumps refused, and the stop
// (not waypoint guidance) when an avoidance plan goes stale.

#include <gtest/gtest.h>

#include "ofn/controller/reference_selector.hpp"

namespace ofn::control {
namespace {

Reference at(const Vec3& position, const Vec3& velocity) {
  Reference r;
  r.position = position;
  r.velocity = velocity;
  return r;
}

TEST(ReferenceSelector, RefusesAPlanThatStartsOffTheReferenceAndTheVehicle) {
  const ReferenceSelector selector;
  const Reference flown = at(Vec3(24, 0, -30), Vec3(0, 0, 0));
  // The 16 m jump of a stale plan resurrected after braking.
  const auto refused = selector.check_start(at(Vec3(40, 0, -30), Vec3(3, 0, 0)), flown,
                                            Vec3(24.1, 0, -30), Vec3::Zero());
  ASSERT_TRUE(refused.has_value());
  EXPECT_NE(refused->find("off the reference flown"), std::string::npos) << *refused;
  // On the reference flown: accepted.
  EXPECT_FALSE(selector
                   .check_start(at(Vec3(24.2, 0, -30), Vec3(0.1, 0, 0)), flown, Vec3(24.1, 0, -30),
                                Vec3::Zero())
                   .has_value());
  // Off the reference but on the vehicle (a plan restarted at the measured
  // state): accepted.
  EXPECT_FALSE(selector
                   .check_start(at(Vec3(28.0, 0, -30), Vec3(0.5, 0, 0)), flown, Vec3(28.3, 0, -30),
                                Vec3(0.4, 0, 0))
                   .has_value());
  // Before any reference is flown, only a start on the vehicle is taken.
  EXPECT_TRUE(selector
                  .check_start(at(Vec3(40, 0, -30), Vec3::Zero()), std::nullopt, Vec3(24, 0, -30),
                               Vec3::Zero())
                  .has_value());
  Reference bad = at(Vec3(24, 0, -30), Vec3::Zero());
  bad.acceleration.x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_TRUE(selector.check_start(bad, flown, Vec3(24, 0, -30), Vec3::Zero()).has_value());
}

TEST(ReferenceSelector, AStalePlanIsFollowedByItsStopAndAHover) {
  ReferenceSelector selector;
  EXPECT_FALSE(selector.avoiding());
  selector.plan_flown();
  ASSERT_TRUE(selector.avoiding());
  const double max_accel = 0.4877;
  Reference flown = at(Vec3(10, 0, -30), Vec3(3.0, 0, 0));
  flown.acceleration = Vec3(0.2, 0, 0);  // still speeding up
  const Reference first = selector.safe_stop(100.0, flown, max_accel);
  EXPECT_TRUE(selector.stopping());
  EXPECT_LT((first.position - flown.position).norm(), 1e-12);  // continuous
  EXPECT_LT((first.velocity - flown.velocity).norm(), 1e-12);
  EXPECT_LT((first.acceleration - flown.acceleration).norm(), 1e-12);
  // The stop is fixed at its start: later calls ignore the reference passed.
  // It is braking.hpp's: the onset from the reference's acceleration,
  // constant deceleration, then the ease-out.
  const StopProfile expected =
      stop_from(flown.position, flown.velocity, flown.acceleration, 0.8 * max_accel);
  const Reference end = selector.safe_stop(100.0 + expected.stop_time + 5.0,
                                           at(Vec3::Zero(), Vec3::Zero()), max_accel);
  EXPECT_NEAR(end.position.x(), expected.stop_point().x(), 1e-9);
  EXPECT_GT(end.position.x(), 10.0 + 3.0 * 3.0 / (2 * 0.8 * max_accel));
  EXPECT_LT(end.velocity.norm(), 1e-12);
  EXPECT_LT(end.acceleration.norm(), 1e-12);
  // Two seconds in, at full deceleration.
  const Reference mid = selector.safe_stop(102.0, flown, max_accel);
  EXPECT_NEAR(mid.velocity.x(), expected.speed_at(2.0), 1e-9);
  EXPECT_NEAR(mid.acceleration.x(), -0.8 * max_accel, 1e-9);
  // A fresh plan ends the stop; the hand-back ends the avoidance.
  selector.plan_flown();
  EXPECT_FALSE(selector.stopping());
  selector.hand_back();
  EXPECT_FALSE(selector.avoiding());
}

TEST(ReferenceSelector, TheHoldBeforeAMissionBrakesFromTheVehiclesState) {
  ReferenceSelector selector;
  // Held in trimmed cruise at 3 m/s until the controller engages: the
  // reference starts on the vehicle, builds up to 0.4 m/s^2 and hovers.
  const Reference first = selector.hold(1.0, Vec3(0, 0, -30), Vec3(3, 0, 0), true);
  EXPECT_LT((first.velocity - Vec3(3, 0, 0)).norm(), 1e-12);
  EXPECT_LT(first.acceleration.norm(), 1e-12);
  EXPECT_NEAR(
      selector.hold(1.0 + kStopOnsetTime, Vec3(99, 0, 0), Vec3::Zero(), false).acceleration.norm(),
      0.4, 1e-9);
  const Reference later = selector.hold(20.0, Vec3(99, 0, 0), Vec3::Zero(), false);
  // v^2 / (2 a), half the onset at the speed less a tau^2 / 24 for its
  // curve, and a tau^2 / 24 for the ease-out.
  const double onset = kStopOnsetTime, ramp = kStopRampTime;
  EXPECT_NEAR(later.position.x(),
              0.5 * 3.0 * 3.0 / 0.4 + 0.5 * 3.0 * onset + 0.4 * (ramp * ramp - onset * onset) / 24,
              1e-9);
  EXPECT_LT(later.velocity.norm(), 1e-12);
}

TEST(ReferenceSelector, AReferenceLapsesAfterItsLapseTime) {
  SelectorSettings settings;
  settings.lapse_time = 0.2;
  const ReferenceSelector selector(settings);
  EXPECT_FALSE(selector.lapsed(0.01));  // one control step
  EXPECT_FALSE(selector.lapsed(0.2));
  EXPECT_TRUE(selector.lapsed(0.21));
  EXPECT_TRUE(selector.lapsed(3.0));  // a loop stopped for 3 s
}

}  // namespace
}  // namespace ofn::control
