// Where in a cell the hits lie, and whether a beam passed over them or
// beside them.

#include <gtest/gtest.h>

#include <cmath>

#include "ofn/mapper/hit_spread.hpp"

namespace ofn::mapping {
namespace {

TEST(HitSpread, ABeamAcrossAFaceHasHitsOnBothSidesOneBesideACornerDoesNot) {
  HitSpread spread(1.0);
  // A face along east at north 10.2, hit across the cell (10, 3).
  for (double east = 3.05; east < 4.0; east += 0.1) spread.add(Vec3(10.2, east, -20));
  // A beam from the south crossing the face at east 3.5: hits on both sides.
  EXPECT_TRUE(spread.straddled(10.5, 3.5, Vec3(0, 3.5, -30), Vec3(30, 3.5, -10), 0.1));
  // The same beam shifted to east 3.98: the hits all lie on one side.
  EXPECT_FALSE(spread.straddled(10.5, 3.5, Vec3(0, 3.98, -30), Vec3(30, 3.98, -10), 0.1));
  // A corner: hits only near (10.2, 3.05), a beam passing 3 cm beside it.
  HitSpread corner(1.0);
  for (double d = 0; d < 0.05; d += 0.01) corner.add(Vec3(10.2 + d, 3.05 + d, -20));
  EXPECT_FALSE(corner.straddled(10.5, 3.5, Vec3(0, 3.02, -30), Vec3(30, 3.02, -10), 0.05));
}

TEST(HitSpread, ACellWithNoHitsSaysNothingAgainstAndFarCellsAreForgotten) {
  HitSpread spread(1.0);
  EXPECT_TRUE(spread.straddled(5.5, 5.5, Vec3(0, 0, 0), Vec3(10, 10, 0), 0.1));
  spread.add(Vec3(5.2, 5.5, -10));
  spread.add(Vec3(5.8, 5.5, -10));
  spread.add(Vec3(std::nan(""), 5.5, -10));  // ignored
  EXPECT_EQ(spread.size(), 1u);
  // A beam along east through the middle: one hit each side.
  EXPECT_TRUE(spread.straddled(5.5, 5.5, Vec3(5.5, 0, -10), Vec3(5.5, 10, -10), 0.1));
  // A horizontal line of no length decides nothing for the cell.
  EXPECT_FALSE(spread.straddled(5.5, 5.5, Vec3(5.5, 5.5, -10), Vec3(5.5, 5.5, -20), 0.1));
  spread.forget_beyond(Vec3(100, 100, 0), 10.0);
  EXPECT_EQ(spread.size(), 0u);
  EXPECT_THROW(HitSpread(0.0), std::invalid_argument);
}

}  // namespace
}  // namespace ofn::mapping
