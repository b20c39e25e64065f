#include "core/log/msgs/inline_string.h"

#include <gtest/gtest.h>

#include <string>
#include <type_traits>

namespace rover::log {
namespace {

static_assert(std::is_trivially_copyable_v<FrameId>);
static_assert(sizeof(FrameId) == 64);
static_assert(FrameId::kCapacity == 63);
// Literals are checked at compile time: 63 chars fit, 64 do not.
static_assert(std::is_convertible_v<const char (&)[64], FrameId>);
static_assert(!std::is_convertible_v<const char (&)[65], FrameId>);
static_assert(!std::is_constructible_v<FrameId, const char (&)[65]>);
// Usable in constant expressions.
static_assert(FrameId("odom").view() == "odom");
static_assert(FrameId("odom").size() == 4);

TEST(InlineStringTest, DefaultIsEmpty) {
  const FrameId id;
  EXPECT_TRUE(id.empty());
  EXPECT_EQ(id.size(), 0u);
  EXPECT_EQ(id.view(), "");
  EXPECT_STREQ(id.c_str(), "");
}

TEST(InlineStringTest, ConstructsFromLiteral) {
  FrameId id = "base_link";
  EXPECT_EQ(id.view(), "base_link");
  EXPECT_STREQ(id.c_str(), "base_link");
  id = "map";
  EXPECT_EQ(id.view(), "map");
  EXPECT_EQ(id, FrameId("map"));
}

TEST(InlineStringTest, FromStringRejectsTooLongAndEmbeddedNul) {
  const std::string exactly_63(63, 'a');
  const std::string too_long(64, 'a');
  ASSERT_TRUE(FrameId::FromString(exactly_63).has_value());
  EXPECT_EQ(FrameId::FromString(exactly_63)->view(), exactly_63);
  EXPECT_FALSE(FrameId::FromString(too_long).has_value());
  EXPECT_FALSE(FrameId::FromString(std::string_view("a\0b", 3)).has_value());
}

TEST(InlineStringTest, AssignLeavesValueUnchangedOnFailure) {
  FrameId id = "imu";
  EXPECT_FALSE(id.Assign(std::string(100, 'x')));
  EXPECT_EQ(id.view(), "imu");
  EXPECT_TRUE(id.Assign("camera_left"));
  EXPECT_EQ(id.view(), "camera_left");
}

TEST(InlineStringTest, ShorterAssignmentClearsTheTail) {
  // Equality compares every byte, so the old tail must be zeroed.
  FrameId a = "camera_left_optical";
  ASSERT_TRUE(a.Assign("cam"));
  EXPECT_EQ(a, FrameId("cam"));
  a.clear();
  EXPECT_EQ(a, FrameId());
}

TEST(InlineStringTest, TruncatedCutsAtCapacity) {
  const std::string text(100, 'z');
  EXPECT_EQ(FrameId::Truncated(text).view(), std::string(63, 'z'));
  EXPECT_EQ(FrameId::Truncated("short").view(), "short");
  EXPECT_EQ(FrameId::Truncated(std::string_view("ab\0cd", 5)).view(), "ab");
}

TEST(InlineStringTest, TruncatedNeverSplitsUtf8) {
  // 62 ASCII bytes then "é" (0xC3 0xA9): cutting at 63 would split it.
  const std::string text = std::string(62, 'a') + "\xC3\xA9" + "tail";
  const FrameId id = FrameId::Truncated(text);
  EXPECT_EQ(id.view(), std::string(62, 'a'));
  // A 2-byte character that ends exactly at the capacity is kept whole.
  const std::string fits = std::string(61, 'a') + "\xC3\xA9" + "tail";
  EXPECT_EQ(FrameId::Truncated(fits).view(), std::string(61, 'a') + "\xC3\xA9");
}

TEST(InlineStringTest, OtherCapacities) {
  using Tiny = InlineString<3>;
  static_assert(sizeof(Tiny) == 4);
  EXPECT_TRUE(Tiny::FromString("abc").has_value());
  EXPECT_FALSE(Tiny::FromString("abcd").has_value());
  EXPECT_EQ(Tiny::Truncated("abcd").view(), "abc");
}

}  // namespace
}  // namespace rover::log
