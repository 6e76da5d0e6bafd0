#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "ofn/controller/command_gate.hpp"

namespace ofn::control {
namespace {

// The benchmark courses' limits in SI: 10 ft/s, 5 ft/s vertical, 1.6 ft/s^2.
Limits course_limits() {
  Limits l;
  l.max_speed = 3.048;
  l.max_vertical_speed = 1.524;
  l.max_accel = 0.48768;
  return l;
}

Reference at(const Vec3& p, const Vec3& v, const Vec3& a) {
  Reference r;
  r.position = p;
  r.velocity = v;
  r.acceleration = a;
  return r;
}

TEST(CommandGate, TakesAMissionWithinTheAirframeAndTheFence) {
  const CommandGate gate;
  EXPECT_FALSE(gate.check_mission(course_limits(), {{Vec3(-30, 0, -6), 3}, {Vec3(150, 0, -6), 3}}));
}

TEST(CommandGate, RefusesAMissionThatRaisesALimitBeyondTheAirframe) {
  const CommandGate gate;
  Limits l = course_limits();
  l.max_speed = 10.5;
  EXPECT_EQ(gate.check_mission(l, {}).value_or(""),
            "speed limit 10.5 m/s above the airframe's 10 m/s");
  l = course_limits();
  l.max_vertical_speed = 4;
  EXPECT_TRUE(gate.check_mission(l, {}));
  l = course_limits();
  l.max_accel = std::numeric_limits<double>::quiet_NaN();
  EXPECT_TRUE(gate.check_mission(l, {}));
}

TEST(CommandGate, RefusesAMissionWithAWaypointOutsideTheFence) {
  const CommandGate gate;
  const auto why =
      gate.check_mission(course_limits(), {{Vec3(0, 0, -6), 3}, {Vec3(0, 0, -400), 3}});
  EXPECT_EQ(why.value_or(""), "waypoint 2 outside the geofence (0 m north)");
}

TEST(CommandGate, APlanInsideTheEnvelopeWithinTwoPerCentIsTaken) {
  const CommandGate gate;
  const Limits l = course_limits();
  EXPECT_FALSE(gate.check_plan({0.0, 1.0},
                               {at(Vec3(0, 0, -6), Vec3(1.019 * l.max_speed, 0, 0), Vec3::Zero()),
                                at(Vec3(3, 0, -6), Vec3(0, 0, 1.019 * l.max_vertical_speed),
                                   Vec3(0, 1.019 * l.max_accel, 0))},
                               l));
}

TEST(CommandGate, APlanThatLeavesTheEnvelopeAnywhereIsRefused) {
  const CommandGate gate;
  const Limits l = course_limits();
  const Reference fine = at(Vec3(0, 0, -6), Vec3(3, 0, 0), Vec3::Zero());
  EXPECT_EQ(
      gate.check_plan({0.0, 0.5},
                      {fine, at(Vec3(1, 0, -6), Vec3(1.03 * l.max_speed, 0, 0), Vec3::Zero())}, l)
          .value_or(""),
      "leaves the envelope at 0.50 s (1.03 of a limit)");
  EXPECT_TRUE(
      gate.check_plan({0.0, 0.5}, {fine, at(Vec3(1, 0, -6), Vec3(0, 0, 1.6), Vec3::Zero())}, l));
  EXPECT_TRUE(
      gate.check_plan({0.0, 0.5}, {fine, at(Vec3(1, 0, -6), Vec3::Zero(), Vec3(0.6, 0, 0))}, l));
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_TRUE(
      gate.check_plan({0.0, 0.5}, {fine, at(Vec3(1, 0, -6), Vec3(nan, 0, 0), Vec3::Zero())}, l));
  EXPECT_TRUE(
      gate.check_plan({0.0, 0.5}, {fine, at(Vec3(1, 0, -6), Vec3::Zero(), Vec3(0, 0, nan))}, l));
  EXPECT_TRUE(
      gate.check_plan({0.0, 0.5}, {fine, at(Vec3(2500, 0, -6), Vec3::Zero(), Vec3::Zero())}, l));
}

TEST(CommandGate, OnlyThePresentAndTheFutureOfAPlanAreChecked) {
  // A plan started on a vehicle a little over the limit, 0.5 s ago: its past
  // is not checked, as the optimiser's commit gate does not check it.
  const CommandGate gate;
  const Limits l = course_limits();
  const std::vector<double> times{0.0, 0.2, 0.4, 0.6, 0.8};
  std::vector<Reference> samples(5, at(Vec3(0, 0, -6), Vec3(3, 0, 0), Vec3::Zero()));
  samples[0].velocity.x() = 1.05 * l.max_speed;
  EXPECT_TRUE(gate.check_plan(times, samples, l, 0.0));
  EXPECT_TRUE(gate.check_plan(times, samples, l, 0.1));  // interpolated from it now
  EXPECT_FALSE(gate.check_plan(times, samples, l, 0.5));
  // The last sample is the plan's end: never past.
  samples.back().velocity.x() = 1.05 * l.max_speed;
  EXPECT_TRUE(gate.check_plan(times, samples, l, 5.0));
}

TEST(CommandGate, ClampsAReferenceIntoTheEnvelopeAndTheFence) {
  const CommandGate gate;
  const Limits l = course_limits();
  bool clamped = true;
  const Reference inside = at(Vec3(10, 0, -6), Vec3(2.8, 0, -1), Vec3(0.4, 0, 0));
  const Reference same = gate.clamp(inside, l, &clamped);
  EXPECT_FALSE(clamped);
  EXPECT_EQ(same.velocity, inside.velocity);

  const Reference wild = at(Vec3(2100, 0, -6), Vec3(15, 0, -5), Vec3(3, 4, 0));
  const Reference r = gate.clamp(wild, l, &clamped);
  EXPECT_TRUE(clamped);
  EXPECT_DOUBLE_EQ(r.position.x(), 2000.0);
  EXPECT_LE(r.velocity.x(), 0.0);  // nothing further out of the fence
  EXPECT_LE(std::abs(r.velocity.z()), 1.02 * l.max_vertical_speed + 1e-12);
  EXPECT_LE(r.velocity.norm(), 1.02 * l.max_speed + 1e-12);
  EXPECT_NEAR(r.acceleration.norm(), 1.02 * l.max_accel, 1e-12);
}

TEST(CommandGate, SettingsThatCannotBeAGateAreRefused) {
  CommandGateSettings s;
  s.max_speed = 0;
  EXPECT_THROW(CommandGate{s}, std::invalid_argument);
  s = CommandGateSettings{};
  s.fence_min.x() = s.fence_max.x();
  EXPECT_THROW(CommandGate{s}, std::invalid_argument);
}

}  // namespace
}  // namespace ofn::control
