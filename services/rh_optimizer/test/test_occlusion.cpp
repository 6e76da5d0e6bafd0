// Unseen space behind a seen face is taken as obstacle until a beam crosses
// it near flight altitude.

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "ofn/rh_optimizer/commit_gate.hpp"
#include "ofn/rh_optimizer/occlusion.hpp"

namespace ofn::rh {
namespace {

/// 100 x 60 cells of 1 m from (0, -30); a face one cell thick at north 50.
mapping::Heightfield face(float top) {
  mapping::Heightfield g;
  g.origin_north = 0;
  g.origin_east = -30;
  g.resolution = 1;
  g.rows = 100;
  g.cols = 60;
  g.top.assign(g.rows * g.cols, 0.0f);
  for (int c = 25; c < 35; ++c) g.at(50, c) = top;
  return g;
}

TEST(OcclusionShadows, HiddenSpaceBehindATallFaceBecomesObstacle) {
  auto g = face(60.0f);
  const VisibilityRecord nothing_seen;
  const int raised = cast_occlusion_shadows(g, nothing_seen, Vec3(0, 0, -30), 30.0, 20.0);
  EXPECT_GT(raised, 100);
  // Straight behind the face, within the depth: obstacle as tall as it.
  EXPECT_FLOAT_EQ(g.at(60, 30), 60.0f);
  EXPECT_FLOAT_EQ(g.at(69, 30), 60.0f);
  // Beyond the depth, and in front of the face: untouched.
  EXPECT_FLOAT_EQ(g.at(75, 30), 0.0f);
  EXPECT_FLOAT_EQ(g.at(45, 30), 0.0f);
  // Off to the side of the line of sight: untouched.
  EXPECT_FLOAT_EQ(g.at(60, 5), 0.0f);
}

TEST(OcclusionShadows, AFaceLowerThanTheVehicleHidesNothing) {
  auto g = face(20.0f);
  EXPECT_EQ(cast_occlusion_shadows(g, VisibilityRecord(), Vec3(0, 0, -30), 30.0, 20.0), 0);
  EXPECT_FLOAT_EQ(g.at(60, 30), 0.0f);
}

TEST(OcclusionShadows, SeenCellsStopTheShadow) {
  auto g = face(60.0f);
  VisibilityRecord seen(1.0, 3.0);
  // A level beam at flight altitude from beside the face across north 58.
  seen.add_beam(Vec3(58.2, -25, -30), Vec3(58.2, 25, -30), false, 30.0);
  cast_occlusion_shadows(g, seen, Vec3(0, 0, -30), 30.0, 20.0);
  EXPECT_FLOAT_EQ(g.at(55, 30), 60.0f);  // between face and the seen line
  EXPECT_FLOAT_EQ(g.at(58, 30), 0.0f);   // seen free
  EXPECT_FLOAT_EQ(g.at(62, 30), 0.0f);   // the shadow stopped there
}

TEST(VisibilityRecord, MarksWhatABeamCrossesNearFlightAltitudeOnly) {
  VisibilityRecord v(1.0, 3.0);
  // A level beam that hits something at north 20: cells up to 19 seen, the
  // hit cell not.
  v.add_beam(Vec3(0.5, 0.5, -30), Vec3(20.5, 0.5, -30), true, 30.0);
  EXPECT_TRUE(v.seen(5.5, 0.5));
  EXPECT_TRUE(v.seen(18.5, 0.5));
  EXPECT_FALSE(v.seen(20.5, 0.5));
  // A steep beam to the ground: only the stretch within 3 m of 30 m counts.
  VisibilityRecord steep(1.0, 3.0);
  steep.add_beam(Vec3(0.5, 0.5, -30), Vec3(30.5, 0.5, 0.0), true, 30.0);
  EXPECT_TRUE(steep.seen(1.5, 0.5));
  EXPECT_FALSE(steep.seen(15.5, 0.5));
  // Forgetting keeps only the neighbourhood.
  v.forget_beyond(Vec3(0, 0, 0), 10.0);
  EXPECT_TRUE(v.seen(5.5, 0.5));
  EXPECT_FALSE(v.seen(18.5, 0.5));
}

TEST(VisibilityRecord, ABeamCountsOnlyAsFarAsItsReach) {
  // A scan point 3.4e38 m away once grew the record by gigabytes in one
  // beam (found by the bus fuzz): a beam counts to max_reach, without a
  // hit, however far it ends.
  VisibilityRecord v(1.0, 3.0, 100.0);
  v.add_beam(Vec3(0.5, 0.5, -30), Vec3(std::numeric_limits<float>::max(), 0.5, -30), true, 30.0);
  EXPECT_TRUE(v.seen(99.5, 0.5));
  EXPECT_FALSE(v.seen(101.5, 0.5));
  EXPECT_LE(v.size(), 101u);
  v.add_beam(Vec3(0.5, 0.5, -30), Vec3(1e300, -1e300, -30), false, 30.0);
  EXPECT_LE(v.size(), 202u);
  // A shorter beam is as before: its hit cell not marked.
  VisibilityRecord near(1.0, 3.0, 100.0);
  near.add_beam(Vec3(0.5, 0.5, -30), Vec3(20.5, 0.5, -30), true, 30.0);
  EXPECT_TRUE(near.seen(18.5, 0.5));
  EXPECT_FALSE(near.seen(20.5, 0.5));
}

TEST(VisibilityRecord, AWayIsSeenOnlyWhenEveryCellOfItIs) {
  VisibilityRecord record(1.0, 3.0);
  VisibilityRecord& v = record;
  // Level beams north along east 0.5 and east along north 10.5, to 20 m.
  v.add_beam(Vec3(0.5, 0.5, -30), Vec3(20.5, 0.5, -30), false, 30.0);
  v.add_beam(Vec3(10.5, 0.5, -30), Vec3(10.5, 20.5, -30), false, 30.0);
  const SeenQuery seen = [&](double n, double e) { return record.seen(n, e); };
  EXPECT_TRUE(way_seen(seen, Vec3(0.5, 0.5, -30), Vec3(19.5, 0.5, -30)));
  // The altitude of the ends does not matter: the record is of cells.
  EXPECT_TRUE(way_seen(seen, Vec3(0.5, 0.5, -30), Vec3(10.5, 0.5, -50)));
  // Along the first beam, then on along the second: seen; diagonally across
  // the unseen corner between them: not.
  EXPECT_TRUE(way_seen(seen, Vec3(10.5, 0.5, -30), Vec3(10.5, 19.5, -30)));
  EXPECT_FALSE(way_seen(seen, Vec3(0.5, 0.5, -30), Vec3(10.5, 19.5, -30)));
  // Past the end of a beam: not.
  EXPECT_FALSE(way_seen(seen, Vec3(0.5, 0.5, -30), Vec3(25.5, 0.5, -30)));
  // A way of no length is its one cell; bad input is never seen.
  EXPECT_TRUE(way_seen(seen, Vec3(5.5, 0.5, -30), Vec3(5.5, 0.5, -30)));
  EXPECT_FALSE(way_seen(seen, Vec3(5.5, 0.5, -30), Vec3(NAN, 0.5, -30)));
  EXPECT_FALSE(way_seen(seen, Vec3(5.5, 0.5, -30), Vec3(6.5, 0.5, -30), 0.0));
  EXPECT_FALSE(way_seen(SeenQuery{}, Vec3(5.5, 0.5, -30), Vec3(5.5, 0.5, -30)));
}

/// Level beams at flight altitude (30 m) from the vehicle at (0, 0) to every
/// cell of `g` whose bearing is within `half_angle` of north, stopping at the
/// first obstacle cell (a hit), as the yaw sweep would look.
VisibilityRecord look_ahead(const mapping::Heightfield& g, double half_angle) {
  VisibilityRecord seen(1.0, 3.0);
  for (double bearing = -half_angle; bearing <= half_angle; bearing += 0.002) {
    const Vec3 direction(std::cos(bearing), std::sin(bearing), 0.0);
    double range = 0.5;
    bool hit = false;
    for (; range < 90.0; range += 0.25) {
      const Vec3 p = range * direction;
      const int r = g.row_of(p.x()), c = g.col_of(p.y());
      if (!g.inside(r, c)) break;
      if (g.at(r, c) > 0.0f) {
        hit = true;
        break;
      }
    }
    seen.add_beam(Vec3(0, 0, -30), Vec3(range * direction.x(), range * direction.y(), -30), hit,
                  30.0);
  }
  return seen;
}

TEST(UnseenExtension, AnObstacleSeenAtTheEdgeOfTheLookGoesOnIntoWhatWasNotSeen) {
  // The corner of a low box hit at the edge of a +-20 deg look: the cells
  // beside it that no beam crossed become obstacle of unknown height; the
  // seen ones, those farther than the reach and those nearer the vehicle
  // stay free.
  mapping::Heightfield g = face(0.0f);
  g.at(40, 44) = 25.0f;  // (40.5, 14.5): bearing 19.7 deg, the edge of the look
  const VisibilityRecord seen = look_ahead(g, deg2rad(20.0));
  ASSERT_TRUE(seen.seen(30.5, 0.5));    // straight ahead was looked at
  ASSERT_FALSE(seen.seen(40.5, 17.5));  // beside the corner was not
  const int raised =
      extend_into_unseen(mapping::Heightfield(g), g, seen, Vec3(0, 0, -30), 3.0, 1.0f, 70.0f);
  EXPECT_GT(raised, 5);
  EXPECT_FLOAT_EQ(g.at(40, 44), 25.0f);  // the seen obstacle keeps its top
  EXPECT_FLOAT_EQ(g.at(40, 47), 70.0f);  // 3 m beside it, unseen: unknown height
  EXPECT_FLOAT_EQ(g.at(42, 46), 70.0f);
  EXPECT_FLOAT_EQ(g.at(40, 48), 0.0f);  // beyond the reach
  EXPECT_FLOAT_EQ(g.at(40, 40), 0.0f);  // inside the look: seen free
  EXPECT_FLOAT_EQ(g.at(38, 45), 0.0f);  // nearer the vehicle than the corner
  // Once a beam has crossed a cell it is free again.
  mapping::Heightfield again = face(0.0f);
  again.at(40, 44) = 25.0f;
  const VisibilityRecord wider = look_ahead(again, deg2rad(40.0));
  EXPECT_TRUE(wider.seen(40.5, 17.5));
  extend_into_unseen(mapping::Heightfield(again), again, wider, Vec3(0, 0, -30), 3.0, 1.0f, 70.0f);
  EXPECT_FLOAT_EQ(again.at(40, 47), 0.0f);
}

TEST(UnseenExtension, ShadowsNeitherExtendNorGrow) {
  // A shadow cell (in the grid, not in the mapped cells) beside unseen
  // space extends nothing, and an obstacle beside it does not raise it.
  mapping::Heightfield mapped = face(0.0f);
  mapped.at(40, 44) = 25.0f;
  mapping::Heightfield grid = mapped;
  grid.at(60, 30) = 40.0f;  // a shadow far from the obstacle
  grid.at(41, 45) = 30.0f;  // a shadow right beside it
  extend_into_unseen(mapped, grid, VisibilityRecord(), Vec3(0, 0, -30), 3.0, 1.0f, 70.0f);
  EXPECT_FLOAT_EQ(grid.at(60, 33), 0.0f);
  EXPECT_FLOAT_EQ(grid.at(41, 45), 30.0f);
  EXPECT_FLOAT_EQ(grid.at(40, 47), 70.0f);  // the mapped obstacle still extends
}

TEST(UnseenExtension, NothingWithoutReachOrBelowTheObstacleTop) {
  mapping::Heightfield g = face(0.0f);
  g.at(40, 44) = 25.0f;
  EXPECT_EQ(extend_into_unseen(mapping::Heightfield(g), g, VisibilityRecord(), Vec3(0, 0, -30), 0.0,
                               1.0f, 70.0f),
            0);
  // A cell no higher than min_top is ground, not an obstacle to extend.
  EXPECT_EQ(extend_into_unseen(mapping::Heightfield(g), g, VisibilityRecord(), Vec3(0, 0, -30), 3.0,
                               25.0f, 70.0f),
            0);
  EXPECT_FLOAT_EQ(g.at(40, 47), 0.0f);
}

TEST(UnseenNear, UnseenCellsInTheRingBecomeObstacleSeenOnesDoNot) {
  mapping::Heightfield g = face(0.0f);
  // The vehicle at (20, 0); a beam along east = 0 to the north has seen
  // that lane, nothing else has been looked at.
  VisibilityRecord seen;
  seen.add_beam(Vec3(20, 0, -30), Vec3(60, 0, -30), false, 30.0);
  const Vec3 vehicle(20, 0, -30);
  const int raised = raise_unseen_near(g, seen, vehicle, 4.0, 10.0, 70.0f);
  EXPECT_GT(raised, 200);
  int counted = 0;
  for (int r = 0; r < g.rows; ++r)
    for (int c = 0; c < g.cols; ++c) {
      const double range =
          std::hypot(g.cell_centre_north(r) - vehicle.x(), g.cell_centre_east(c) - vehicle.y());
      const bool looked = seen.seen(g.cell_centre_north(r), g.cell_centre_east(c));
      const bool expect_raised = range >= 4.0 && range <= 10.0 && !looked;
      EXPECT_FLOAT_EQ(g.at(r, c), expect_raised ? 70.0f : 0.0f) << "row " << r << " col " << c;
      counted += expect_raised;
    }
  EXPECT_EQ(raised, counted);
  // Beside the vehicle, inside the exempt radius: left alone; beyond the
  // reach: left alone; on the seen lane: left alone.
  EXPECT_FLOAT_EQ(g.at(g.row_of(20.5), g.col_of(2.5)), 0.0f);
  EXPECT_FLOAT_EQ(g.at(g.row_of(20.5), g.col_of(15.5)), 0.0f);
  EXPECT_FLOAT_EQ(g.at(g.row_of(27.5), g.col_of(0.5)), 0.0f);
  EXPECT_FLOAT_EQ(g.at(g.row_of(27.5), g.col_of(6.5)), 70.0f);
}

TEST(UnseenNear, NothingWithoutARingAndNoCellLowered) {
  mapping::Heightfield g = face(0.0f);
  EXPECT_EQ(raise_unseen_near(g, VisibilityRecord(), Vec3(20, 0, -30), 10.0, 10.0, 70.0f), 0);
  EXPECT_EQ(raise_unseen_near(g, VisibilityRecord(), Vec3(20, 0, -30), 4.0, 0.0, 70.0f), 0);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(raise_unseen_near(g, VisibilityRecord(), Vec3(nan, 0, -30), 4.0, 10.0, 70.0f), 0);
  // A mapped cell taller than the unknown top keeps its own height.
  g.at(g.row_of(26.5), g.col_of(0.5)) = 90.0f;
  raise_unseen_near(g, VisibilityRecord(), Vec3(20, 0, -30), 4.0, 10.0, 70.0f);
  EXPECT_FLOAT_EQ(g.at(g.row_of(26.5), g.col_of(0.5)), 90.0f);
  EXPECT_FLOAT_EQ(g.at(g.row_of(26.5), g.col_of(1.5)), 70.0f);
}

}  // namespace
}  // namespace ofn::rh
