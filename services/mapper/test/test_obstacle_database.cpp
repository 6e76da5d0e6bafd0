// The obstacle database: insertion, update, merging, misses and retirement
// of the cuboids extracted each global-planning cycle.

#include <gtest/gtest.h>

#include <vector>

#include "ofn/mapper/cuboid_extractor.hpp"
#include "ofn/mapper/obstacle_database.hpp"

namespace ofn::mapping {
namespace {

Cuboid box(double min_north, double min_east, double max_north, double max_east, double top) {
  Cuboid c;
  c.min = Vec3(min_north, min_east, -top);
  c.max = Vec3(max_north, max_east, 0);
  return c;
}

const auto kAllInView = [](const Cuboid&) { return true; };
const auto kNoneInView = [](const Cuboid&) { return false; };

std::vector<int> ids_of(const ObstacleDatabase& db) {
  std::vector<int> ids;
  for (const auto& e : db.entries()) ids.push_back(e.id);
  return ids;
}

TEST(FootprintOverlap, IsIntersectionOverSmallerFootprint) {
  EXPECT_DOUBLE_EQ(footprint_overlap(box(0, 0, 10, 10, 5), box(2, 2, 4, 4, 5)), 1.0);
  EXPECT_DOUBLE_EQ(footprint_overlap(box(0, 0, 10, 10, 5), box(5, 0, 15, 10, 5)), 0.5);
  EXPECT_DOUBLE_EQ(footprint_overlap(box(0, 0, 10, 10, 5), box(10, 0, 20, 10, 5)), 0.0);
  EXPECT_DOUBLE_EQ(footprint_overlap(box(0, 0, 10, 10, 5), box(30, 30, 40, 40, 5)), 0.0);
}

TEST(ObstacleDatabase, InsertsUnmatchedCuboids) {
  ObstacleDatabase db{ObstacleDatabaseConfig{}};
  db.update({box(0, 0, 10, 10, 20), box(50, 50, 60, 60, 30)}, 1000, kAllInView);
  ASSERT_EQ(db.entries().size(), 2u);
  EXPECT_EQ(ids_of(db), (std::vector<int>{1, 2}));
  EXPECT_EQ(db.inserted(), 2);
  for (const auto& e : db.entries()) {
    EXPECT_DOUBLE_EQ(e.confidence, 0.25);
    EXPECT_EQ(e.first_seen, 1000);
    EXPECT_EQ(e.last_seen, 1000);
    EXPECT_EQ(e.misses, 0);
  }
  EXPECT_DOUBLE_EQ(db.entries()[1].cuboid.top_altitude(), 30.0);
}

TEST(ObstacleDatabase, UpdateKeepsIdAndTakesNewExtent) {
  ObstacleDatabase db{ObstacleDatabaseConfig{}};
  db.update({box(0, 0, 10, 10, 20)}, 1000, kAllInView);
  db.update({box(1, 2, 12, 11, 26)}, 2000, kAllInView);
  ASSERT_EQ(db.entries().size(), 1u);
  const auto& e = db.entries()[0];
  EXPECT_EQ(e.id, 1);
  EXPECT_EQ(e.cuboid.min, Vec3(1, 2, -26));
  EXPECT_EQ(e.cuboid.max, Vec3(12, 11, 0));
  EXPECT_EQ(e.first_seen, 1000);
  EXPECT_EQ(e.last_seen, 2000);
  EXPECT_EQ(db.inserted(), 1);
}

TEST(ObstacleDatabase, CuboidBridgingTwoEntriesMergesThemIntoLowerId) {
  ObstacleDatabase db{ObstacleDatabaseConfig{}};
  db.update({box(0, 0, 10, 10, 20), box(12, 0, 22, 10, 20)}, 1000, kAllInView);
  ASSERT_EQ(ids_of(db), (std::vector<int>{1, 2}));
  db.update({box(0, 0, 22, 10, 24)}, 2000, kAllInView);
  ASSERT_EQ(db.entries().size(), 1u);
  EXPECT_EQ(db.entries()[0].id, 1);
  EXPECT_EQ(db.entries()[0].cuboid.max, Vec3(22, 10, 0));
  EXPECT_DOUBLE_EQ(db.entries()[0].cuboid.top_altitude(), 24.0);
  EXPECT_EQ(db.merged(), 1);
  EXPECT_EQ(db.retired(), 0);
}

TEST(ObstacleDatabase, EntryInViewAndMissingIsRetiredAfterMisses) {
  ObstacleDatabaseConfig config;
  config.retire_after_misses = 3;
  ObstacleDatabase db{config};
  db.update({box(0, 0, 10, 10, 20)}, 1000, kAllInView);
  for (int cycle = 1; cycle < 3; ++cycle) {
    db.update({}, 1000 + cycle * 1000, kAllInView);
    ASSERT_EQ(db.entries().size(), 1u) << "cycle " << cycle;
    EXPECT_EQ(db.entries()[0].misses, cycle);
  }
  db.update({}, 4000, kAllInView);
  EXPECT_TRUE(db.entries().empty());
  EXPECT_EQ(db.retired(), 1);
  EXPECT_EQ(db.merged(), 0);
}

TEST(ObstacleDatabase, SightingClearsMisses) {
  ObstacleDatabase db{ObstacleDatabaseConfig{}};  // retired after 2 misses
  db.update({box(0, 0, 10, 10, 20)}, 1000, kAllInView);
  db.update({}, 2000, kAllInView);
  db.update({box(0, 0, 10, 10, 20)}, 3000, kAllInView);
  ASSERT_EQ(db.entries().size(), 1u);
  EXPECT_EQ(db.entries()[0].misses, 0);
  db.update({}, 4000, kAllInView);
  EXPECT_EQ(db.entries().size(), 1u);
}

TEST(ObstacleDatabase, EntryOutOfViewIsKeptUnchanged) {
  ObstacleDatabase db{ObstacleDatabaseConfig{}};
  db.update({box(0, 0, 10, 10, 20)}, 1000, kAllInView);
  for (int cycle = 1; cycle <= 50; ++cycle) db.update({}, 1000 + cycle * 1000, kNoneInView);
  ASSERT_EQ(db.entries().size(), 1u);
  EXPECT_EQ(db.entries()[0].misses, 0);
  EXPECT_DOUBLE_EQ(db.entries()[0].confidence, 0.25);
  EXPECT_EQ(db.entries()[0].last_seen, 1000);
  EXPECT_EQ(db.retired(), 0);
}

TEST(ObstacleDatabase, EmptyViewCheckCountsEverythingInView) {
  ObstacleDatabase db{ObstacleDatabaseConfig{}};
  db.update({box(0, 0, 10, 10, 20)}, 1000, {});
  db.update({}, 2000, {});
  db.update({}, 3000, {});
  EXPECT_TRUE(db.entries().empty());
}

TEST(ObstacleDatabase, ConfidenceRisesWithSightingsAndFallsWithMisses) {
  ObstacleDatabaseConfig config;
  config.retire_after_misses = 10;
  ObstacleDatabase db{config};
  const std::vector<double> rising{0.25, 0.5, 0.75, 1.0, 1.0};
  for (size_t i = 0; i < rising.size(); ++i) {
    db.update({box(0, 0, 10, 10, 20)}, 1000 * (i + 1), kAllInView);
    EXPECT_DOUBLE_EQ(db.entries()[0].confidence, rising[i]);
  }
  const std::vector<double> falling{0.75, 0.5, 0.25, 0.0, 0.0};
  for (size_t i = 0; i < falling.size(); ++i) {
    db.update({}, 10000 + 1000 * i, kAllInView);
    EXPECT_DOUBLE_EQ(db.entries()[0].confidence, falling[i]);
  }
}

TEST(ObstacleDatabase, SecondCuboidMatchingAClaimedEntryIsInserted) {
  ObstacleDatabase db{ObstacleDatabaseConfig{}};
  db.update({box(0, 0, 10, 10, 20)}, 1000, kAllInView);
  db.update({box(0, 0, 10, 5, 20), box(0, 5, 10, 10, 20)}, 2000, kAllInView);
  ASSERT_EQ(ids_of(db), (std::vector<int>{1, 2}));
  EXPECT_EQ(db.entries()[0].cuboid.max.y(), 5.0);
  EXPECT_EQ(db.entries()[1].cuboid.min.y(), 5.0);
  EXPECT_EQ(db.merged(), 0);
}

TEST(ObstacleDatabase, StaircasePiecesStaySeparateEntriesWithStableIds) {
  Heightfield grid;
  grid.rows = 40;
  grid.cols = 41;
  grid.top.assign(static_cast<size_t>(grid.rows) * grid.cols, 0.0f);
  for (int i = 0; i < 40; ++i) grid.at(i, i) = grid.at(i, i + 1) = 25.0f;
  const auto staircase = CuboidExtractor{CuboidExtractorConfig{}}.extract(grid);
  ASSERT_GE(staircase.size(), 4u);

  ObstacleDatabase db{ObstacleDatabaseConfig{}};
  db.update(staircase, 1000, kAllInView);
  const auto first_ids = ids_of(db);
  ASSERT_EQ(first_ids.size(), staircase.size());
  for (int cycle = 2; cycle <= 6; ++cycle) {
    db.update(staircase, 1000 * cycle, kAllInView);
    EXPECT_EQ(ids_of(db), first_ids) << "cycle " << cycle;
  }
  EXPECT_EQ(db.inserted(), static_cast<int>(staircase.size()));
  EXPECT_EQ(db.merged(), 0);
  EXPECT_EQ(db.retired(), 0);
  ASSERT_EQ(db.entries().size(), staircase.size());
  for (const auto& e : db.entries()) EXPECT_DOUBLE_EQ(e.confidence, 1.0);
}

}  // namespace
}  // namespace ofn::mapping
