#include "ofn/mapper/voxel_key_set.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <set>
#include <vector>

namespace ofn::mapping {
namespace {

TEST(VoxelKeySet, PacksAndUnpacksEveryIndex) {
  for (const std::uint16_t x : {0, 1, 32768, 65535})
    for (const std::uint16_t y : {0, 7, 65535})
      for (const std::uint16_t z : {0, 12345, 65535}) {
        const std::uint64_t key = VoxelKeySet::pack(x, y, z);
        EXPECT_EQ(VoxelKeySet::x_of(key), x);
        EXPECT_EQ(VoxelKeySet::y_of(key), y);
        EXPECT_EQ(VoxelKeySet::z_of(key), z);
      }
  // The largest key is still an ordinary key.
  VoxelKeySet set;
  const std::uint64_t largest = VoxelKeySet::pack(65535, 65535, 65535);
  EXPECT_FALSE(set.contains(largest));
  EXPECT_TRUE(set.insert(largest));
  EXPECT_TRUE(set.contains(largest));
}

TEST(VoxelKeySet, HoldsWhatAnOrderedSetHoldsThroughGrowthAndClears) {
  std::mt19937 rng(5);
  // Voxels of a small block, as a scan's rays give them: many repeats.
  std::uniform_int_distribution<int> index(32700, 32830);
  VoxelKeySet set;
  for (int round = 0; round < 6; ++round) {
    // Rounds of different sizes: the table grows, then is cleared with
    // many keys (a full sweep) and with few (slot by slot).
    const int inserts = round % 2 ? 300 : 40000;
    std::set<std::uint64_t> expected;
    std::vector<std::uint64_t> first_seen;
    for (int i = 0; i < inserts; ++i) {
      const std::uint64_t key = VoxelKeySet::pack(static_cast<std::uint16_t>(index(rng)),
                                                  static_cast<std::uint16_t>(index(rng)),
                                                  static_cast<std::uint16_t>(index(rng) % 64));
      const bool is_new = expected.insert(key).second;
      EXPECT_EQ(set.insert(key), is_new);
      if (is_new) first_seen.push_back(key);
    }
    ASSERT_EQ(set.size(), expected.size());
    EXPECT_EQ(set.keys(), first_seen);  // in the order of first insertion
    for (const std::uint64_t key : expected) EXPECT_TRUE(set.contains(key));
    for (int i = 0; i < 2000; ++i) {
      const std::uint64_t key = VoxelKeySet::pack(static_cast<std::uint16_t>(index(rng)),
                                                  static_cast<std::uint16_t>(index(rng)), 100);
      EXPECT_FALSE(set.contains(key));  // z 100 is never inserted
    }
    set.clear();
    EXPECT_TRUE(set.empty());
    for (const std::uint64_t key : expected) ASSERT_FALSE(set.contains(key));
  }
}

TEST(VoxelKeySet, ASlotBySlotClearFindsKeysPastCollisions) {
  // Enough keys that many probe past others, yet few enough (under an
  // eighth of the table) that the clear goes slot by slot: each key must
  // still be found where its probe sequence put it.
  VoxelKeySet set;
  for (std::uint16_t x = 0; x < 200; ++x)
    for (std::uint16_t y = 0; y < 200; ++y) set.insert(VoxelKeySet::pack(x, y, 0));
  set.clear();  // the table keeps its size: 131072 slots
  std::vector<std::uint64_t> keys;
  for (std::uint16_t x = 0; x < 125; ++x)
    for (std::uint16_t y = 0; y < 128; ++y) keys.push_back(VoxelKeySet::pack(x, y, 1));
  for (const std::uint64_t key : keys) ASSERT_TRUE(set.insert(key));
  set.clear();
  for (const std::uint64_t key : keys) ASSERT_FALSE(set.contains(key));
  for (const std::uint64_t key : keys) ASSERT_TRUE(set.insert(key));
  EXPECT_EQ(set.size(), keys.size());
}

}  // namespace
}  // namespace ofn::mapping
