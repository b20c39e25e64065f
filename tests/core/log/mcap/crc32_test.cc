#include "core/log/mcap/crc32.h"

#include <gtest/gtest.h>

#include <random>
#include <string_view>
#include <vector>

namespace rover::log {
namespace {

std::span<const std::byte> Bytes(std::string_view s) { return std::as_bytes(std::span(s)); }

// Bit-at-a-time reference straight from the definition (reflected 0xEDB88320).
uint32_t ReferenceCrc32(std::span<const std::byte> data) {
  uint32_t c = 0xFFFFFFFFU;
  for (const std::byte b : data) {
    c ^= static_cast<uint32_t>(b);
    for (int bit = 0; bit < 8; ++bit) c = (c & 1U) != 0 ? (c >> 1) ^ 0xEDB88320U : c >> 1;
  }
  return ~c;
}

TEST(Crc32Test, KnownVectors) {
  EXPECT_EQ(Crc32({}), 0U);
  EXPECT_EQ(Crc32(Bytes("123456789")), 0xCBF43926U);
  EXPECT_EQ(Crc32(Bytes("The quick brown fox jumps over the lazy dog")), 0x414FA339U);
}

TEST(Crc32Test, MatchesBitwiseReferenceAtAllLengthsAndAlignments) {
  std::mt19937 rng(7);
  std::vector<std::byte> data(300);
  for (auto& b : data) b = static_cast<std::byte>(rng() & 0xFFU);
  for (size_t start = 0; start < 9; ++start) {
    for (size_t len = 0; len + start <= data.size(); len += 7) {
      const auto part = std::span(data).subspan(start, len);
      ASSERT_EQ(Crc32(part), ReferenceCrc32(part)) << "start " << start << " len " << len;
    }
  }
}

TEST(Crc32Test, ChainsLikeZlib) {
  const auto all = Bytes("hello, rover flight log");
  for (size_t cut = 0; cut <= all.size(); ++cut) {
    EXPECT_EQ(Crc32(all.subspan(cut), Crc32(all.first(cut))), Crc32(all));
  }
}

}  // namespace
}  // namespace rover::log
