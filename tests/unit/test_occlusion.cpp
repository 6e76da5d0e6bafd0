// Unseen space behind a seen face is taken as obstacle until a beam crosses
// it near flight altitude.

#include <gtest/gtest.h>

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

}  // namespace
}  // namespace ofn::rh
