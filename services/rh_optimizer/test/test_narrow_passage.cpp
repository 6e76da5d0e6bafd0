// Pinches on a global route: gaps the RH optimiser cannot fly through with
// its clearance (R_s plus its margin from the mapped cells), found by
// climbing the clearance across the route, and the memory of them that
// goes to the global planner.

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "ofn/rh_optimizer/narrow_passage.hpp"
#include "rh_step_inputs.hpp"

namespace ofn::rh {
namespace {

using testing_support::Box;
using testing_support::field_with;
using testing_support::kBenchmarkLimits;
using testing_support::kLegAltitude;

// The optimiser's clearance on the benchmarks: R_s plus its 0.5 m margin.
const double kRequired = kBenchmarkLimits.clearance + 0.5;

// A route north along east = `east` at the leg altitude, a point every 2 m.
std::vector<Vec3> route_north(double from, double to, double east) {
  std::vector<Vec3> route;
  for (double n = from; n <= to + 1e-9; n += 2.0) route.emplace_back(n, east, -kLegAltitude);
  return route;
}

// Two tall blocks north 50..70 either side of east = 0, `gap` m apart.
ClearanceQuery gap_of(int gap) {
  const int half = gap / 2;
  return field_with({Box{50, 70, -40, -half, 60.0f}, Box{50, 70, half, 40, 60.0f}});
}

TEST(NarrowPassage, AGapNarrowerThanTwiceTheClearanceIsAPinch) {
  const ClearanceQuery clearance = gap_of(12);
  const auto pinch = find_narrow_passage(clearance, route_north(0, 120, 0.0), kRequired);
  ASSERT_TRUE(pinch.has_value());
  // In the gap, at its widest (the middle), with less than the clearance.
  EXPECT_GE(pinch->centre.x(), 48.0);
  EXPECT_LE(pinch->centre.x(), 72.0);
  EXPECT_LT(std::abs(pinch->centre.y()), 1.0);
  EXPECT_LT(pinch->clearance, kRequired);
  EXPECT_GT(pinch->clearance, 4.0);
  // Any way through the gap passes within the radius of the centre.
  EXPECT_GE(pinch->radius, 6.0);
  EXPECT_LT(pinch->radius, kRequired + 1.0);
  // The zone is the gap's column: from at least 40 m below the route (the
  // search's reach; the blocks stand on the ground) up to where the
  // clearance over the 60 m tops is reached (just above them: the gap
  // lacks little), and no higher.
  const double top = -(pinch->centre.z() - pinch->half_height);
  const double bottom = -(pinch->centre.z() + pinch->half_height);
  EXPECT_LE(bottom, kLegAltitude - 40.0 + 1e-6);
  EXPECT_GT(top, 60.0);
  EXPECT_LE(top, 60.0 + kRequired + 1.5);
}

TEST(NarrowPassage, TheColumnOfALowGapEndsWhereItCanBeFlownOver) {
  // Blocks 34 m tall, the route at 30 m: the zone ends where the
  // clearance over the gap is reached, so a route over the blocks (at R_s
  // above them) stays open.
  const ClearanceQuery clearance =
      field_with({Box{50, 70, -40, -6, 34.0f}, Box{50, 70, 6, 40, 34.0f}});
  const auto pinch = find_narrow_passage(clearance, route_north(0, 120, 0.0), kRequired);
  ASSERT_TRUE(pinch.has_value());
  const double top = -(pinch->centre.z() - pinch->half_height);
  EXPECT_GT(top, 34.0);
  EXPECT_LT(top, 34.0 + kBenchmarkLimits.clearance);
  EXPECT_FALSE(
      find_narrow_passage(clearance, route_north(0, 120, 0.0), kRequired, PassageSettings{false}));
}

TEST(NarrowPassage, AWideEnoughGapIsNoPinchWhereverTheRouteCrossesIt) {
  // 18 m: 9 m of room from the middle. A route 3 m off the middle is 6 m
  // from a block, short of the clearance, but a trajectory beside it is not.
  const ClearanceQuery clearance = gap_of(18);
  EXPECT_FALSE(find_narrow_passage(clearance, route_north(0, 120, 0.0), kRequired));
  EXPECT_FALSE(find_narrow_passage(clearance, route_north(0, 120, 3.0), kRequired));
}

TEST(NarrowPassage, ARouteAlongAWallAtTheCuboidClearanceIsNoPinch) {
  // The global planner's nodes sit R_s from a cuboid: within the
  // optimiser's margin, which it keeps by passing a little farther out.
  const ClearanceQuery clearance = field_with({Box{50, 70, 6, 40, 60.0f}});
  const auto route = route_north(0, 120, 0.0);
  EXPECT_LT(clearance(Vec3(60, 0, -kLegAltitude)).distance, kRequired);
  EXPECT_FALSE(find_narrow_passage(clearance, route, kRequired));
}

TEST(NarrowPassage, OnlyTheRoutesFirstLookDistanceIsChecked) {
  const ClearanceQuery clearance = gap_of(12);
  PassageSettings near;
  near.look_distance = 30.0;  // the gap begins 50 m on
  EXPECT_FALSE(find_narrow_passage(clearance, route_north(0, 120, 0.0), kRequired, near));
  near.enabled = false;
  near.look_distance = 200.0;
  EXPECT_FALSE(find_narrow_passage(clearance, route_north(0, 120, 0.0), kRequired, near));
}

TEST(NarrowPassage, APinchRoundTheRoutesStartIsPassedOver) {
  // The vehicle stopped in the middle of the gap: the planner lets routes
  // leave a zone round their start, so such a zone would change nothing.
  // What is reported is the gap farther on, clear of the start: the route
  // then backs out.
  const ClearanceQuery clearance = gap_of(12);
  const auto route = route_north(60, 170, 0.0);
  const auto pinch = find_narrow_passage(clearance, route, kRequired);
  ASSERT_TRUE(pinch.has_value());
  EXPECT_GT((pinch->centre - route.front()).head<2>().norm(), pinch->radius);
  EXPECT_LE(pinch->centre.x(), 72.0);
}

TEST(NarrowPassage, NoQueryOrTooShortARouteFindsNothing) {
  EXPECT_FALSE(find_narrow_passage(ClearanceQuery(), route_north(0, 120, 0.0), kRequired));
  EXPECT_FALSE(find_narrow_passage(gap_of(12), {Vec3(60, 0, -kLegAltitude)}, kRequired));
}

// A route that bends in a gap: it may pass the corner, but an escape leg
// stopping there has no room to stop with the clearance.
TEST(CrampedStop, AStopInAGapNarrowerThanTwiceTheClearanceHasNoRoom) {
  const ClearanceQuery clearance = gap_of(12);
  const Vec3 corner(60.0, 0.0, -kLegAltitude);
  const auto zone = find_cramped_stop(clearance, corner, kRequired);
  ASSERT_TRUE(zone.has_value());
  EXPECT_LT(zone->clearance, kRequired);
  // Round the stop, over the disc without room.
  EXPECT_EQ(zone->centre.head<2>(), corner.head<2>());
  EXPECT_DOUBLE_EQ(zone->radius, PassageSettings{}.max_shift + 0.5);
  // The column goes up to about the tops.
  const double top = -(zone->centre.z() - zone->half_height);
  EXPECT_GT(top, 60.0);
  EXPECT_LE(top, 60.0 + kRequired + 1.5);
  // Wide enough, or the corner 10 m before the gap: room to stop.
  EXPECT_FALSE(find_cramped_stop(gap_of(16), corner, kRequired).has_value());
  EXPECT_FALSE(find_cramped_stop(clearance, Vec3(40.0, 0.0, -kLegAltitude), kRequired).has_value());
  EXPECT_FALSE(find_cramped_stop(ClearanceQuery{}, corner, kRequired).has_value());
}

// One search for both: where the check finds room at a corner, the escape's
// end is the nearest such point; where it finds none, there is no end.
TEST(RoomToStop, TheNearestPointWithTheClearanceIsWhereTheStopIsMade) {
  const Vec3 corner(60.0, 0.0, -kLegAltitude);
  // The corner in the 12 m gap: no room; 10 m before it, room.
  EXPECT_FALSE(room_to_stop(gap_of(12), corner, kRequired, 3.0).has_value());
  const Vec3 before(40.0, 0.0, -kLegAltitude);
  const auto free = room_to_stop(gap_of(12), before, kRequired, 3.0);
  ASSERT_TRUE(free.has_value());
  EXPECT_EQ(*free, before);
  // No gradient anywhere, room only east of 1.4 m: the nearest sample
  // there, 1.5 m due east.
  const ClearanceQuery east_is_clear = [](const Vec3& p) {
    mapping::DistanceSample s;
    s.distance = p.y() > 1.4 ? 7.0 : 5.0;
    return s;
  };
  const auto moved = room_to_stop(east_is_clear, corner, 6.6, 3.0);
  ASSERT_TRUE(moved.has_value());
  EXPECT_NEAR(moved->x(), corner.x(), 1e-9);
  EXPECT_NEAR(moved->y(), 1.5, 1e-9);
  EXPECT_EQ(moved->z(), corner.z());
  EXPECT_FALSE(room_to_stop(east_is_clear, corner, 6.6, 1.0).has_value());
  // Up the gradient past the samples' spacing: a wall to the west.
  const ClearanceQuery wall = [](const Vec3& p) {
    mapping::DistanceSample s;
    s.distance = 6.0 + p.y();
    s.gradient = Vec3::UnitY();
    return s;
  };
  const auto climbed = room_to_stop(wall, corner, 6.6, 3.0);
  ASSERT_TRUE(climbed.has_value());
  EXPECT_GE(wall(*climbed).distance, 6.6);
  EXPECT_LE(climbed->y(), 1.0 + 1e-9);
  // Agreement with the check, corner by corner along the gap's approach.
  for (double north = 30.0; north <= 70.0; north += 2.5) {
    const Vec3 stop(north, 0.0, -kLegAltitude);
    EXPECT_EQ(room_to_stop(gap_of(12), stop, kRequired, 3.0).has_value(),
              !find_cramped_stop(gap_of(12), stop, kRequired).has_value())
        << north;
  }
  EXPECT_FALSE(room_to_stop(ClearanceQuery{}, corner, kRequired, 3.0).has_value());
}

TEST(PassageMemory, KeepsEachPassageOnceAndTheNewestWithinItsCapacity) {
  PassageMemory memory(2);
  const NarrowPassage a{Vec3(60, 0, -30), 6.0, 3.0, 5.5};
  EXPECT_TRUE(memory.add(a));
  // The same gap found again from a route a little to the side.
  EXPECT_FALSE(memory.add(NarrowPassage{Vec3(61, 2, -31), 6.0, 3.0, 5.4}));
  // The same spot 10 m higher is another passage.
  EXPECT_TRUE(memory.add(NarrowPassage{Vec3(60, 0, -40), 6.0, 3.0, 5.0}));
  EXPECT_TRUE(memory.add(NarrowPassage{Vec3(120, 0, -30), 6.0, 3.0, 5.0}));
  ASSERT_EQ(memory.passages().size(), 2u);
  EXPECT_EQ(memory.passages().front().centre, Vec3(60, 0, -40));
  memory.clear();
  EXPECT_TRUE(memory.passages().empty());
}

}  // namespace
}  // namespace ofn::rh
