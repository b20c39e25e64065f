#include "core/log/cdr/cdr_writer.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <limits>
#include <memory>
#include <vector>

#include "tests/support/allocation_counter.h"

namespace rover::log {
namespace {

using ::testing::ElementsAreArray;

std::vector<std::byte> Bytes(std::initializer_list<int> values) {
  std::vector<std::byte> out;
  for (const int v : values) out.push_back(static_cast<std::byte>(v));
  return out;
}

std::vector<std::byte> ToVector(std::span<const std::byte> bytes) {
  return {bytes.begin(), bytes.end()};
}

TEST(CdrWriterTest, WritesLittleEndianEncapsulationHeader) {
  std::array<std::byte, 16> buffer{};
  CdrWriter writer(buffer);
  EXPECT_TRUE(writer.ok());
  EXPECT_EQ(writer.size(), 4u);
  EXPECT_THAT(ToVector(writer.data()), ElementsAreArray(Bytes({0x00, 0x01, 0x00, 0x00})));
}

TEST(CdrWriterTest, AlignsPrimitivesRelativeToPayloadStartWithZeroPadding) {
  std::array<std::byte, 64> buffer;
  buffer.fill(std::byte{0xAA});  // Padding must overwrite stale bytes with zeros.
  CdrWriter writer(buffer);
  writer.WriteU8(0x11);         // payload 0
  writer.WriteU16(0x2233);      // payload 2 (1 pad)
  writer.WriteU8(0x44);         // payload 4
  writer.WriteU32(0x55667788);  // payload 8 (3 pad)
  writer.WriteBool(true);       // payload 12
  writer.WriteF64(1.0);         // payload 16 (3 pad)
  writer.WriteI16(-2);          // payload 24
  writer.WriteI64(-1);          // payload 32 (6 pad)
  ASSERT_TRUE(writer.ok());
  EXPECT_THAT(ToVector(writer.data()),
              ElementsAreArray(Bytes({0x00, 0x01, 0x00, 0x00,                          //
                                      0x11, 0x00, 0x33, 0x22, 0x44, 0x00, 0x00, 0x00,  //
                                      0x88, 0x77, 0x66, 0x55, 0x01, 0x00, 0x00, 0x00,  //
                                      0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xF0, 0x3F,  //
                                      0xFE, 0xFF, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,  //
                                      0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF})));
}

TEST(CdrWriterTest, WritesStringsWithLengthIncludingNul) {
  std::array<std::byte, 32> buffer{};
  CdrWriter writer(buffer);
  writer.WriteU8(7);
  writer.WriteString("ab");
  writer.WriteString("");
  ASSERT_TRUE(writer.ok());
  EXPECT_THAT(ToVector(writer.data()),
              ElementsAreArray(Bytes({0x00, 0x01, 0x00, 0x00,  //
                                      0x07, 0x00, 0x00, 0x00,  // u8 + pad to 4
                                      0x03, 0x00, 0x00, 0x00, 'a', 'b', 0x00,
                                      0x00,  // pad to 4 for the next length
                                      0x01, 0x00, 0x00, 0x00, 0x00})));
}

TEST(CdrWriterTest, WritesSequencesAndArrays) {
  std::array<std::byte, 64> buffer{};
  CdrWriter writer(buffer);
  const std::array<uint8_t, 3> octets = {1, 2, 3};
  writer.WriteSequenceSize(octets.size());
  writer.WriteU8Array(octets);
  const std::array<double, 2> doubles = {0.0, -2.0};
  writer.WriteF64Array(doubles);  // Aligned to 8: payload 7 -> 8.
  ASSERT_TRUE(writer.ok());
  EXPECT_THAT(ToVector(writer.data()),
              ElementsAreArray(Bytes({0x00, 0x01, 0x00, 0x00,                          //
                                      0x03, 0x00, 0x00, 0x00, 0x01, 0x02, 0x03, 0x00,  //
                                      0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,  //
                                      0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xC0})));
}

TEST(CdrWriterTest, EmptyDoubleArrayAddsNoPadding) {
  std::array<std::byte, 16> buffer{};
  CdrWriter writer(buffer);
  writer.WriteU8(1);
  writer.WriteF64Array({});
  EXPECT_EQ(writer.size(), 5u);
}

TEST(CdrWriterTest, OverflowSetsFailedFlagAndKeepsCountingRequiredSize) {
  std::array<std::byte, 10> buffer{};
  CdrWriter writer(buffer);
  writer.WriteU32(1);  // Ends at 8.
  EXPECT_TRUE(writer.ok());
  writer.WriteU64(2);  // Would end at 4 + 16 = 20.
  EXPECT_FALSE(writer.ok());
  EXPECT_EQ(writer.size(), 8u);
  writer.WriteU8(3);  // Not stored, but counted.
  EXPECT_FALSE(writer.ok());
  EXPECT_EQ(writer.size(), 8u);
  EXPECT_EQ(writer.required_size(), 21u);
  EXPECT_EQ(writer.data().size(), 8u);
}

TEST(CdrWriterTest, BufferTooSmallForHeaderFails) {
  std::array<std::byte, 3> buffer{};
  CdrWriter writer(buffer);
  EXPECT_FALSE(writer.ok());
  EXPECT_EQ(writer.size(), 0u);
  writer.WriteU32(5);
  EXPECT_EQ(writer.required_size(), 8u);

  CdrWriter empty{std::span<std::byte>{}};
  EXPECT_FALSE(empty.ok());
  EXPECT_EQ(empty.size(), 0u);
  EXPECT_EQ(empty.required_size(), 4u);
}

TEST(CdrWriterTest, ExactFitIsOk) {
  std::array<std::byte, 12> buffer{};
  CdrWriter writer(buffer);
  writer.WriteU64(9);
  EXPECT_TRUE(writer.ok());
  EXPECT_EQ(writer.size(), 12u);
}

TEST(CdrWriterTest, VectorModeAppendsAndAlignsRelativeToItsOwnPayload) {
  std::vector<std::byte> out = Bytes({0xEE, 0xEE, 0xEE});  // Unaligned existing prefix.
  CdrWriter writer(&out);
  writer.WriteU8(1);
  writer.WriteU32(2);
  ASSERT_TRUE(writer.ok());
  EXPECT_EQ(writer.size(), 12u);
  EXPECT_THAT(out, ElementsAreArray(Bytes({0xEE, 0xEE, 0xEE,        //
                                           0x00, 0x01, 0x00, 0x00,  //
                                           0x01, 0x00, 0x00, 0x00, 0x02, 0x00, 0x00, 0x00})));
  EXPECT_THAT(ToVector(writer.data()), ElementsAreArray(std::span(out).subspan(3)));
}

TEST(CdrWriterTest, VectorModeMatchesFixedBufferMode) {
  std::vector<std::byte> grown;
  std::array<std::byte, 256> buffer{};
  CdrWriter a(&grown);
  CdrWriter b(buffer);
  for (CdrWriter* w : {&a, &b}) {
    w->WriteString("frame");
    w->WriteF64(3.5);
    w->WriteI8(-1);
    w->WriteF32(0.25f);
    w->WriteSequenceSize(0);
  }
  EXPECT_EQ(ToVector(a.data()), ToVector(b.data()));
}

TEST(AllocationCounterTest, CountsHeapAllocations) {
  // Guards the no-allocation tests against a counter that silently never counts.
  const rover::testing::ScopedAllocationCheck check;
  auto block = std::make_unique<std::array<std::byte, 1000>>();
  EXPECT_EQ(check.allocations(), 1u);
  EXPECT_GE(check.allocated_bytes(), 1000u);
  block.reset();
}

TEST(CdrWriterTest, FixedBufferWritesDoNotAllocate) {
  std::array<std::byte, 128> buffer{};
  const std::array<double, 9> covariance{};
  const rover::testing::ScopedAllocationCheck check;
  {
    CdrWriter writer(buffer);
    writer.WriteI32(1);
    writer.WriteString("base_link");
    writer.WriteF64Array(covariance);
    writer.WriteF64Array(covariance);  // Overflows: still no allocation.
  }
  EXPECT_EQ(check.allocations(), 0u);
}

}  // namespace
}  // namespace rover::log
