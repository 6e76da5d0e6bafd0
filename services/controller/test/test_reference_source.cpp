// The control loop's mode machine: which reference each step flies.

#include <gtest/gtest.h>

#include "ofn/controller/reference_source.hpp"

namespace ofn::control {
namespace {

// A flight under way on waypoint guidance, the planner's word fresh.
StepSituation guided_flight() {
  StepSituation s;
  s.previous = ControlMode::kWaypoint;
  s.has_mission = true;
  s.reference_flown = true;
  return s;
}

TEST(ReferenceSource, NoMissionHolds) {
  StepSituation s;  // navigation just arrived, nothing else
  ReferenceChoice c = choose_reference(s);
  EXPECT_EQ(c.source, ReferenceSource::kHold);
  EXPECT_EQ(c.mode, ControlMode::kHold);
  EXPECT_TRUE(c.hold_begins);  // entered from NAV_STALE
  EXPECT_TRUE(c.reset_control);
  s.previous = ControlMode::kHold;
  c = choose_reference(s);
  EXPECT_FALSE(c.hold_begins);  // the same hold goes on
  EXPECT_FALSE(c.reset_control);
  s.lapsed = true;
  c = choose_reference(s);
  EXPECT_TRUE(c.hold_begins);  // begun again from the vehicle
  EXPECT_TRUE(c.reset_control);
  s.lapsed = false;
  // A plan without a mission is not flown.
  s.fresh_plan = true;
  EXPECT_EQ(choose_reference(s).source, ReferenceSource::kHold);
}

TEST(ReferenceSource, AMissionHoldsUntilThePlannerConfirms) {
  StepSituation s;
  s.previous = ControlMode::kHold;
  s.has_mission = true;
  s.mission_arrived = true;
  s.awaiting_planner = true;
  s.map_stale = true;
  ReferenceChoice c = choose_reference(s);
  EXPECT_EQ(c.source, ReferenceSource::kHold);
  EXPECT_TRUE(c.hold_begins);  // the mission's hold starts where the vehicle is
  // and so does the control law: what it learnt while the vehicle was held
  // (or flown by its pilot) is not flown on release.
  EXPECT_TRUE(c.reset_control);
  s.mission_arrived = false;
  c = choose_reference(s);
  EXPECT_FALSE(c.hold_begins);
  EXPECT_FALSE(c.reset_control);
  // A plan arrives before the first confirmation: it is flown, and the
  // control law leaves the hold afresh.
  s.fresh_plan = true;
  c = choose_reference(s);
  EXPECT_EQ(c.source, ReferenceSource::kPlan);
  EXPECT_EQ(c.mode, ControlMode::kTrajectory);
  EXPECT_TRUE(c.reset_control);
  // Confirmed on a fresh map: guidance, from the vehicle.
  s.fresh_plan = false;
  s.awaiting_planner = false;
  s.map_stale = false;
  c = choose_reference(s);
  EXPECT_EQ(c.source, ReferenceSource::kGuidance);
  EXPECT_EQ(c.mode, ControlMode::kWaypoint);
  EXPECT_TRUE(c.resync_guidance);
  EXPECT_TRUE(c.reset_control);
}

TEST(ReferenceSource, AwaitingThePlannerHoldsOnlyBeforeTheFlight) {
  // Once flying, an unconfirmed planner does not bring the hold back; a
  // stale map holds guidance with a stop instead.
  StepSituation s = guided_flight();
  s.awaiting_planner = true;
  s.map_stale = true;
  const ReferenceChoice c = choose_reference(s);
  EXPECT_EQ(c.source, ReferenceSource::kBlindStop);
  EXPECT_EQ(c.mode, ControlMode::kSafeStop);
  EXPECT_FALSE(c.stop_from_vehicle);  // from the reference flown
  // After navigation was lost, the hold comes back until the planner speaks.
  s.previous = ControlMode::kNavStale;
  EXPECT_EQ(choose_reference(s).source, ReferenceSource::kHold);
}

TEST(ReferenceSource, AFreshPlanIsFlown) {
  StepSituation s = guided_flight();
  s.fresh_plan = true;
  s.avoiding = true;
  s.map_stale = true;  // a plan made on an older map is still the plan
  const ReferenceChoice c = choose_reference(s);
  EXPECT_EQ(c.source, ReferenceSource::kPlan);
  EXPECT_EQ(c.mode, ControlMode::kTrajectory);
  EXPECT_FALSE(c.reset_control);
}

TEST(ReferenceSource, AStalePlanMidAvoidanceIsStoppedNeverGuided) {
  StepSituation s = guided_flight();
  s.previous = ControlMode::kTrajectory;
  s.avoiding = true;
  ReferenceChoice c = choose_reference(s);
  EXPECT_EQ(c.source, ReferenceSource::kPlanStop);
  EXPECT_EQ(c.mode, ControlMode::kSafeStop);
  // Also with a fresh map, and after the stop has run into its hover.
  s.previous = ControlMode::kSafeStop;
  s.stopping = true;
  c = choose_reference(s);
  EXPECT_EQ(c.source, ReferenceSource::kPlanStop);
  // Handed back (NOMINAL): guidance again, from the vehicle.
  s.avoiding = false;
  c = choose_reference(s);
  EXPECT_EQ(c.source, ReferenceSource::kGuidance);
  EXPECT_TRUE(c.end_stop);
  EXPECT_TRUE(c.resync_guidance);
}

TEST(ReferenceSource, AStaleMapHoldsGuidanceWithAStop) {
  StepSituation s = guided_flight();
  s.map_stale = true;
  ReferenceChoice c = choose_reference(s);
  EXPECT_EQ(c.source, ReferenceSource::kBlindStop);
  EXPECT_FALSE(c.stop_from_vehicle);
  // With no reference flown (a new mission, a lapse) the stop starts from
  // the vehicle's state.
  s.reference_flown = false;
  EXPECT_TRUE(choose_reference(s).stop_from_vehicle);
  s.reference_flown = true;
  s.previous = ControlMode::kNavStale;
  EXPECT_TRUE(choose_reference(s).stop_from_vehicle);
  // Fresh again: guidance resumes from the vehicle and the stop ends.
  s.previous = ControlMode::kSafeStop;
  s.stopping = true;
  s.map_stale = false;
  c = choose_reference(s);
  EXPECT_EQ(c.source, ReferenceSource::kGuidance);
  EXPECT_TRUE(c.end_stop);
  EXPECT_TRUE(c.resync_guidance);
}

TEST(ReferenceSource, ADoneMissionIgnoresAStaleMap) {
  // At the last waypoint guidance holds the hover there; a planner that
  // goes quiet afterwards changes nothing.
  StepSituation s = guided_flight();
  s.previous = ControlMode::kDone;
  s.map_stale = true;
  const ReferenceChoice c = choose_reference(s);
  EXPECT_EQ(c.source, ReferenceSource::kGuidance);
  EXPECT_FALSE(c.resync_guidance);
  EXPECT_FALSE(c.end_stop);
}

TEST(ReferenceSource, GuidanceGoesOnWithoutResync) {
  const ReferenceChoice c = choose_reference(guided_flight());
  EXPECT_EQ(c.source, ReferenceSource::kGuidance);
  EXPECT_EQ(c.mode, ControlMode::kWaypoint);
  EXPECT_FALSE(c.resync_guidance);
  EXPECT_FALSE(c.reset_control);
  EXPECT_FALSE(c.end_stop);
}

TEST(ReferenceSource, ModeNames) {
  EXPECT_STREQ(to_string(ControlMode::kSafeStop), "SAFE_STOP");
  EXPECT_STREQ(to_string(ControlMode::kNavStale), "NAV_STALE");
  EXPECT_STREQ(to_string(static_cast<ControlMode>(42)), "UNKNOWN");
}

}  // namespace
}  // namespace ofn::control
