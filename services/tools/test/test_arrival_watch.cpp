#include <gtest/gtest.h>

#include "ofn/tools/arrival_watch.hpp"

namespace ofn::report {
namespace {

const Vec3 kGoal(120.0, 5.0, -20.0);
constexpr int32_t kMission = 1;

// Status and navigation at 50 Hz from `from` for `seconds`, at `position`.
void fly(ArrivalWatch& watch, double from, double seconds, const Vec3& position, bool done) {
  for (int i = 0; i < static_cast<int>(seconds * 50.0); ++i) {
    const Utime t = to_utime(from + 0.02 * i);
    watch.on_navigation(t, position);
    watch.on_status(t, done, kMission);
  }
}

TEST(ArrivalWatch, ArrivalNeedsDoneForTheLingerAtTheGoal) {
  ArrivalWatch watch;
  watch.set_goal(kMission, kGoal, 3.0);
  fly(watch, 0.0, 10.0, Vec3(50, 0, -20), false);
  fly(watch, 10.0, 0.9, kGoal + Vec3(1, 0, 0), true);
  EXPECT_FALSE(watch.arrived_at());
  fly(watch, 10.9, 0.2, kGoal + Vec3(1, 0, 0), true);
  ASSERT_TRUE(watch.arrived_at());
  EXPECT_EQ(*watch.arrived_at(), to_utime(10.0));
  EXPECT_EQ(watch.unconfirmed_done(), 0);
}

TEST(ArrivalWatch, OneForgedDoneAmongTheControllersStatusesEndsNothing) {
  ArrivalWatch watch;
  watch.set_goal(kMission, kGoal, 3.0);
  for (int i = 0; i < 500; ++i) {
    const Utime t = to_utime(0.02 * i);
    watch.on_navigation(t, kGoal - Vec3(200, 0, 0) + Vec3(0.2 * i, 0, 0));
    watch.on_status(t, false, kMission);
    if (i == 250) watch.on_status(t, true, kMission);  // a stranger's DONE
  }
  EXPECT_FALSE(watch.arrived_at());
  EXPECT_EQ(watch.unconfirmed_done(), 1);
  EXPECT_EQ(watch.last_doubt(), "vehicle 150.0 m from the last waypoint");
}

TEST(ArrivalWatch, DoneAwayFromTheGoalIsNotArrivalHoweverLong) {
  ArrivalWatch watch;
  watch.set_goal(kMission, kGoal, 3.0);
  fly(watch, 0.0, 5.0, kGoal + Vec3(0, 6, 0), true);
  EXPECT_FALSE(watch.arrived_at());
  EXPECT_EQ(watch.unconfirmed_done(), 250);
}

TEST(ArrivalWatch, AnInterruptedRunOfDoneStartsAgain) {
  ArrivalWatch watch;
  watch.set_goal(kMission, kGoal, 3.0);
  fly(watch, 0.0, 0.8, kGoal, true);
  fly(watch, 0.8, 0.02, kGoal, false);
  fly(watch, 0.82, 0.9, kGoal, true);
  EXPECT_FALSE(watch.arrived_at());
  fly(watch, 1.72, 0.2, kGoal, true);
  ASSERT_TRUE(watch.arrived_at());
  EXPECT_EQ(*watch.arrived_at(), to_utime(0.82));
}

TEST(ArrivalWatch, NoMissionOrNoNavigationProvesNothing) {
  ArrivalWatch watch;
  fly(watch, 0.0, 2.0, kGoal, true);
  EXPECT_FALSE(watch.arrived_at());
  EXPECT_EQ(watch.last_doubt(), "no mission 1 known");
  watch.set_goal(kMission, kGoal, 3.0);
  // Navigation stopped 5 s ago.
  watch.on_status(to_utime(7.0), true, kMission);
  EXPECT_EQ(watch.last_doubt(), "no navigation at that time");
  EXPECT_FALSE(watch.arrived_at());
}

TEST(ArrivalWatch, ANewGoalForTheMissionFlownRestartsTheWatch) {
  ArrivalWatch watch;
  watch.set_goal(kMission, kGoal, 3.0);
  fly(watch, 0.0, 0.9, kGoal, true);
  watch.set_goal(kMission, kGoal + Vec3(100, 0, 0), 3.0);
  fly(watch, 0.9, 0.5, kGoal, true);
  EXPECT_FALSE(watch.arrived_at());
  EXPECT_EQ(watch.unconfirmed_done(), 25);
}

TEST(ArrivalWatch, AStrayMissionOnTheBusDoesNotMoveTheGoalOfTheOneFlown) {
  ArrivalWatch watch;
  watch.set_goal(kMission, kGoal, 3.0);
  fly(watch, 0.0, 0.5, kGoal, true);
  // A forged MISSION with another id and a far goal, many times.
  for (int32_t id = 100; id < 200; ++id) watch.set_goal(id, kGoal + Vec3(500, 0, 0), 3.0);
  // Its goal is gone from the bounded table, but the flown one stays known.
  fly(watch, 0.5, 0.6, kGoal, true);
  ASSERT_TRUE(watch.arrived_at());
  EXPECT_EQ(*watch.arrived_at(), 0);
}

}  // namespace
}  // namespace ofn::report
