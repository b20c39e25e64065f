#include "mapping/submap/key_flag_table.h"

#include <random>
#include <unordered_map>

#include <gtest/gtest.h>

namespace rover::mapping {
namespace {

TEST(KeyFlagTableTest, OrMergesFlagsAndReturnsThePreviousOnes) {
  KeyFlagTable table(64);
  EXPECT_EQ(table.Or(42, 1), 0);
  EXPECT_EQ(table.Or(42, 4), 1);
  EXPECT_EQ(table.Get(42), 5);
  EXPECT_EQ(table.Get(43), 0);
  EXPECT_EQ(table.size(), 1u);
}

TEST(KeyFlagTableTest, KeepsAValuePerKeyThroughGrowth) {
  KeyFlagTable table(64);
  for (uint64_t k = 0; k < 1000; ++k) {
    const KeyFlagTable::Slot slot = table.OrAt(k * 7919, 1);
    ASSERT_EQ(slot.before, 0);
    ASSERT_EQ(table.value(slot.index), 0u);  // fresh keys start at 0
    table.value(slot.index) = static_cast<uint32_t>(k + 1);
  }
  EXPECT_GT(table.capacity(), 64u);
  for (uint64_t k = 0; k < 1000; ++k) {
    const KeyFlagTable::Slot slot = table.OrAt(k * 7919, 2);
    ASSERT_EQ(slot.before, 1);
    ASSERT_EQ(table.value(slot.index), k + 1);
  }
}

TEST(KeyFlagTableTest, GrowsWithoutLosingKeys) {
  KeyFlagTable table(64);
  std::mt19937_64 rng(7);
  std::unordered_map<uint64_t, uint8_t> expected;
  for (int i = 0; i < 100000; ++i) {
    const uint64_t key = rng() & KeyFlagTable::kKeyMask;
    const auto flags = static_cast<uint8_t>(1u << (rng() % 3));
    table.Or(key, flags);
    expected[key] |= flags;
  }
  EXPECT_EQ(table.size(), expected.size());
  EXPECT_GE(table.capacity(), 2 * expected.size());
  for (const auto& [key, flags] : expected) ASSERT_EQ(table.Get(key), flags);
  std::size_t seen = 0;
  table.ForEach([&](uint64_t key, uint8_t flags) {
    ++seen;
    EXPECT_EQ(expected.at(key), flags);
  });
  EXPECT_EQ(seen, expected.size());
}

TEST(KeyFlagTableTest, ClearForgetsEverythingAcrossGenerationWraps) {
  KeyFlagTable table(64);
  for (uint64_t round = 0; round < 700; ++round) {  // wraps the 8-bit generation twice
    table.Clear();
    EXPECT_EQ(table.size(), 0u);
    for (uint64_t k = 0; k < 20; ++k) ASSERT_EQ(table.Or(round * 100 + k, 2), 0);
    if (round > 0) {
      ASSERT_EQ(table.Get((round - 1) * 100), 0);
    }
    std::size_t seen = 0;
    table.ForEach([&](uint64_t, uint8_t) { ++seen; });
    ASSERT_EQ(seen, 20u);
  }
  // Reused, not reallocated: 20 keys never needed more than the start.
  EXPECT_EQ(table.capacity(), 64u);
}

}  // namespace
}  // namespace rover::mapping
