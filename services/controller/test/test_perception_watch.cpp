// PerceptionWatch: waypoint guidance flies on only while the planner's
// word is fresh and was given on a fresh map.

#include <gtest/gtest.h>

#include <limits>

#include "ofn/controller/perception_watch.hpp"

namespace ofn::control {
namespace {

constexpr MissionLeg kLeg{3, 1};

TEST(PerceptionWatch, NothingHeardHoldsGuidance) {
  PerceptionWatch watch;
  ASSERT_TRUE(watch.stale(10.0, kLeg));
  EXPECT_EQ(*watch.stale(10.0, kLeg), "no planner status yet");
  EXPECT_FALSE(watch.confirmed_once());
  watch.on_status(10.0, 0.0, true, kLeg);  // a status, but no map yet
  EXPECT_FALSE(watch.confirmed_once());
  watch.on_status(10.1, 10.05, true, kLeg);
  EXPECT_TRUE(watch.confirmed_once());
}

TEST(PerceptionWatch, FreshStatusOnAFreshMapLetsGuidanceFly) {
  PerceptionWatch watch;
  watch.on_status(10.0, 9.8, true, kLeg);
  EXPECT_FALSE(watch.stale(10.0, kLeg));
  EXPECT_FALSE(watch.stale(10.79, kLeg));  // map 0.99 s old
  EXPECT_TRUE(watch.stale(10.81, kLeg));   // map past 1 s
}

TEST(PerceptionWatch, SilentPlannerOrOldMapHoldsGuidance) {
  PerceptionWatch watch;
  watch.on_status(10.0, 10.0, true, kLeg);
  const auto silent = watch.stale(11.5, kLeg);
  ASSERT_TRUE(silent);
  EXPECT_NE(silent->find("planner silent for 1.5 s"), std::string::npos) << *silent;
  // Statuses keep coming, but on a map that no scan has refreshed.
  PerceptionWatch starved;
  for (double t = 10.0; t <= 12.0; t += 0.1) starved.on_status(t, 10.0, true, kLeg);
  const auto old_map = starved.stale(12.0, kLeg);
  ASSERT_TRUE(old_map);
  EXPECT_NE(old_map->find("map is 2"), std::string::npos) << *old_map;
  // A status without a map (the optimiser has no grid yet).
  PerceptionWatch unmapped;
  unmapped.on_status(10.0, 0.0, true, kLeg);
  ASSERT_TRUE(unmapped.stale(10.0, kLeg));
  EXPECT_EQ(*unmapped.stale(10.0, kLeg), "the planner has no map yet");
  // The planner itself silent: its status ages out whatever its map was.
  PerceptionWatchSettings lenient_map;
  lenient_map.max_map_age = 60.0;
  PerceptionWatch gone_lenient(lenient_map);
  gone_lenient.on_status(10.0, 10.0, true, kLeg);
  ASSERT_TRUE(gone_lenient.stale(11.2, kLeg));
  EXPECT_NE(gone_lenient.stale(11.2, kLeg)->find("planner silent"), std::string::npos);
}

TEST(PerceptionWatch, FreshWordAgainResumesAndOldStatusesAreIgnored) {
  PerceptionWatch watch;
  watch.on_status(10.0, 10.0, true, kLeg);
  ASSERT_TRUE(watch.stale(12.0, kLeg));
  watch.on_status(12.0, 11.9, true, kLeg);
  EXPECT_FALSE(watch.stale(12.0, kLeg));
  watch.on_status(5.0, 5.0, true, kLeg);  // reordered or replayed: not newer
  EXPECT_FALSE(watch.stale(12.1, kLeg));
  watch.on_status(std::numeric_limits<double>::quiet_NaN(), 12.0, true, kLeg);
  EXPECT_FALSE(watch.stale(12.1, kLeg));
}

TEST(PerceptionWatch, GuidanceWaitsWhileThePlannerHasNotClearedTheLeg) {
  PerceptionWatch watch;
  watch.on_status(10.0, 10.0, false, kLeg);  // avoiding: its plans are flown
  ASSERT_TRUE(watch.stale(10.0, kLeg));
  EXPECT_EQ(*watch.stale(10.0, kLeg), "the planner has not cleared the leg");
  watch.on_status(10.1, 10.1, true, kLeg);  // handed back
  EXPECT_FALSE(watch.stale(10.1, kLeg));
}

TEST(PerceptionWatch, AClearWordHoldsForItsOwnLegOnly) {
  PerceptionWatch watch;
  watch.on_status(10.0, 10.0, true, MissionLeg{3, 2});
  // Guidance on another leg of the same mission (a route flown out and
  // back: the planner watches the way back) or on another mission.
  for (const MissionLeg flown : {MissionLeg{3, 1}, MissionLeg{4, 2}, MissionLeg{3, -1}}) {
    const auto why = watch.stale(10.0, flown);
    ASSERT_TRUE(why);
    EXPECT_NE(why->find("cleared the leg to waypoint 2 of mission 3"), std::string::npos) << *why;
  }
  EXPECT_FALSE(watch.stale(10.0, MissionLeg{3, 2}));
  // The leg of the newest status; an older one, reordered, does not count.
  EXPECT_EQ(watch.checked(), (MissionLeg{3, 2}));
  watch.on_status(9.9, 9.9, true, MissionLeg{3, 1});
  EXPECT_EQ(watch.checked(), (MissionLeg{3, 2}));
}

TEST(PerceptionWatch, DisabledNeverHolds) {
  PerceptionWatchSettings off;
  off.enabled = false;
  PerceptionWatch watch(off);
  EXPECT_FALSE(watch.stale(100.0, kLeg));
}

}  // namespace
}  // namespace ofn::control
