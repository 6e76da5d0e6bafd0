// PerceptionWatch: waypoint guidance flies on only while the planner's
// word is fresh and was given on a fresh map.

#include <gtest/gtest.h>

#include <limits>

#include "ofn/controller/perception_watch.hpp"

namespace ofn::control {
namespace {

TEST(PerceptionWatch, NothingHeardHoldsGuidance) {
  PerceptionWatch watch;
  ASSERT_TRUE(watch.stale(10.0));
  EXPECT_EQ(*watch.stale(10.0), "no planner status yet");
  EXPECT_FALSE(watch.confirmed_once());
  watch.on_status(10.0, 0.0, true);  // a status, but no map yet
  EXPECT_FALSE(watch.confirmed_once());
  watch.on_status(10.1, 10.05, true);
  EXPECT_TRUE(watch.confirmed_once());
}

TEST(PerceptionWatch, FreshStatusOnAFreshMapLetsGuidanceFly) {
  PerceptionWatch watch;
  watch.on_status(10.0, 9.8, true);
  EXPECT_FALSE(watch.stale(10.0));
  EXPECT_FALSE(watch.stale(10.79));  // map 0.99 s old
  EXPECT_TRUE(watch.stale(10.81));   // map past 1 s
}

TEST(PerceptionWatch, SilentPlannerOrOldMapHoldsGuidance) {
  PerceptionWatch watch;
  watch.on_status(10.0, 10.0, true);
  const auto silent = watch.stale(11.5);
  ASSERT_TRUE(silent);
  EXPECT_NE(silent->find("planner silent for 1.5 s"), std::string::npos) << *silent;
  // Statuses keep coming, but on a map that no scan has refreshed.
  PerceptionWatch starved;
  for (double t = 10.0; t <= 12.0; t += 0.1) starved.on_status(t, 10.0, true);
  const auto old_map = starved.stale(12.0);
  ASSERT_TRUE(old_map);
  EXPECT_NE(old_map->find("map is 2"), std::string::npos) << *old_map;
  // A status without a map (the optimiser has no grid yet).
  PerceptionWatch unmapped;
  unmapped.on_status(10.0, 0.0, true);
  ASSERT_TRUE(unmapped.stale(10.0));
  EXPECT_EQ(*unmapped.stale(10.0), "the planner has no map yet");
  // The planner itself silent: its status ages out whatever its map was.
  PerceptionWatchSettings lenient_map;
  lenient_map.max_map_age = 60.0;
  PerceptionWatch gone_lenient(lenient_map);
  gone_lenient.on_status(10.0, 10.0, true);
  ASSERT_TRUE(gone_lenient.stale(11.2));
  EXPECT_NE(gone_lenient.stale(11.2)->find("planner silent"), std::string::npos);
}

TEST(PerceptionWatch, FreshWordAgainResumesAndOldStatusesAreIgnored) {
  PerceptionWatch watch;
  watch.on_status(10.0, 10.0, true);
  ASSERT_TRUE(watch.stale(12.0));
  watch.on_status(12.0, 11.9, true);
  EXPECT_FALSE(watch.stale(12.0));
  watch.on_status(5.0, 5.0, true);  // reordered or replayed: not newer
  EXPECT_FALSE(watch.stale(12.1));
  watch.on_status(std::numeric_limits<double>::quiet_NaN(), 12.0, true);
  EXPECT_FALSE(watch.stale(12.1));
}

TEST(PerceptionWatch, GuidanceWaitsWhileThePlannerHasNotClearedTheLeg) {
  PerceptionWatch watch;
  watch.on_status(10.0, 10.0, false);  // avoiding: its plans are flown
  ASSERT_TRUE(watch.stale(10.0));
  EXPECT_EQ(*watch.stale(10.0), "the planner has not cleared the leg");
  watch.on_status(10.1, 10.1, true);  // handed back
  EXPECT_FALSE(watch.stale(10.1));
}

TEST(PerceptionWatch, DisabledNeverHolds) {
  PerceptionWatchSettings off;
  off.enabled = false;
  PerceptionWatch watch(off);
  EXPECT_FALSE(watch.stale(100.0));
}

}  // namespace
}  // namespace ofn::control
