#include "core/log/cdr/cdr_reader.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "core/log/cdr/cdr_writer.h"

namespace rover::log {
namespace {

using ::testing::HasSubstr;

std::vector<std::byte> Bytes(std::initializer_list<int> values) {
  std::vector<std::byte> out;
  for (const int v : values) out.push_back(static_cast<std::byte>(v));
  return out;
}

TEST(CdrReaderTest, ReadsBackWhatTheWriterWrote) {
  std::vector<std::byte> bytes;
  {
    CdrWriter w(&bytes);
    w.WriteBool(true);
    w.WriteU8(200);
    w.WriteI8(-100);
    w.WriteU16(60000);
    w.WriteI16(-30000);
    w.WriteU32(4000000000u);
    w.WriteI32(-2000000000);
    w.WriteU64(std::numeric_limits<uint64_t>::max());
    w.WriteI64(std::numeric_limits<int64_t>::min());
    w.WriteF32(1.5f);
    w.WriteF64(-0.125);
    w.WriteString("hello");
    const std::array<uint8_t, 3> octets = {9, 8, 7};
    w.WriteSequenceSize(octets.size());
    w.WriteU8Array(octets);
    const std::array<double, 3> doubles = {1.0, 2.0, 3.0};
    w.WriteF64Array(doubles);
  }
  CdrReader r(bytes, "test");
  bool b = false;
  uint8_t u8 = 0;
  int8_t i8 = 0;
  uint16_t u16 = 0;
  int16_t i16 = 0;
  uint32_t u32 = 0;
  int32_t i32 = 0;
  uint64_t u64 = 0;
  int64_t i64 = 0;
  float f32 = 0;
  double f64 = 0;
  std::string s;
  std::vector<uint8_t> octets;
  std::array<double, 3> doubles{};
  ASSERT_TRUE(r.ReadBool("b", &b) && r.ReadU8("u8", &u8) && r.ReadI8("i8", &i8) &&
              r.ReadU16("u16", &u16) && r.ReadI16("i16", &i16) && r.ReadU32("u32", &u32) &&
              r.ReadI32("i32", &i32) && r.ReadU64("u64", &u64) && r.ReadI64("i64", &i64) &&
              r.ReadF32("f32", &f32) && r.ReadF64("f64", &f64) && r.ReadString("s", &s) &&
              r.ReadU8Sequence("octets", &octets) && r.ReadF64Array("doubles", doubles))
      << r.error();
  EXPECT_TRUE(b);
  EXPECT_EQ(u8, 200);
  EXPECT_EQ(i8, -100);
  EXPECT_EQ(u16, 60000);
  EXPECT_EQ(i16, -30000);
  EXPECT_EQ(u32, 4000000000u);
  EXPECT_EQ(i32, -2000000000);
  EXPECT_EQ(u64, std::numeric_limits<uint64_t>::max());
  EXPECT_EQ(i64, std::numeric_limits<int64_t>::min());
  EXPECT_EQ(f32, 1.5f);
  EXPECT_EQ(f64, -0.125);
  EXPECT_EQ(s, "hello");
  EXPECT_EQ(octets, (std::vector<uint8_t>{9, 8, 7}));
  EXPECT_EQ(doubles, (std::array<double, 3>{1.0, 2.0, 3.0}));
  EXPECT_EQ(r.remaining(), 0u);
  EXPECT_TRUE(r.error().empty());
}

TEST(CdrReaderTest, RejectsMissingOrForeignEncapsulationHeader) {
  {
    const auto bytes = Bytes({0x00, 0x01});
    CdrReader r(bytes, "pkg/msg/T");
    EXPECT_FALSE(r.ok());
    EXPECT_EQ(r.error(),
              "pkg/msg/T: at offset 0: buffer of 2 bytes is too short for the 4-byte CDR "
              "encapsulation header");
  }
  {
    const auto bytes = Bytes({0x00, 0x00, 0x00, 0x00, 0x01});
    CdrReader r(bytes);
    EXPECT_FALSE(r.ok());
    EXPECT_THAT(r.error(), HasSubstr("big-endian CDR"));
  }
  {
    const auto bytes = Bytes({0x00, 0x07, 0x00, 0x00});
    CdrReader r(bytes);
    EXPECT_THAT(r.error(), HasSubstr("unsupported encapsulation 0x0007"));
    uint8_t v = 0;
    EXPECT_FALSE(r.ReadU8("x", &v));  // Failed readers stay failed.
  }
  {
    const auto bytes = Bytes({0x00, 0x01, 0x00, 0x00});  // Options bytes are ignored.
    CdrReader r(bytes);
    EXPECT_TRUE(r.ok());
    EXPECT_EQ(r.offset(), 4u);
  }
}

TEST(CdrReaderTest, TruncatedPrimitiveNamesFieldAndOffset) {
  const auto bytes = Bytes({0x00, 0x01, 0x00, 0x00, 0x01, 0x02, 0x03});
  CdrReader r(bytes, "pkg/msg/T");
  uint8_t a = 0;
  uint32_t b = 0;
  ASSERT_TRUE(r.ReadU8("a", &a));
  EXPECT_FALSE(r.ReadU32("b", &b));
  EXPECT_EQ(r.error(),
            "pkg/msg/T: field 'b' at offset 8: truncated: uint32 needs 4 bytes, 0 remaining");
  EXPECT_EQ(r.offset(), 5u);  // A failed read consumes nothing.
}

TEST(CdrReaderTest, NestedScopesFormTheFieldPath) {
  const auto bytes = Bytes({0x00, 0x01, 0x00, 0x00, 0x01});
  CdrReader r(bytes, "pkg/msg/T");
  const CdrReader::Scope outer = r.EnterField("status");
  const CdrReader::Scope element = r.EnterElement(2);
  const CdrReader::Scope inner = r.EnterField("values");
  const CdrReader::Scope inner_element = r.EnterElement(0);
  double d = 0;
  EXPECT_FALSE(r.ReadF64("x", &d));
  EXPECT_EQ(r.error(),
            "pkg/msg/T: field 'status[2].values[0].x' at offset 4: truncated: float64 needs 8 "
            "bytes, 1 remaining");
}

TEST(CdrReaderTest, FirstErrorIsKept) {
  const auto bytes = Bytes({0x00, 0x01, 0x00, 0x00});
  CdrReader r(bytes);
  uint8_t v = 0;
  EXPECT_FALSE(r.ReadU8("first", &v));
  EXPECT_FALSE(r.ReadU8("second", &v));
  EXPECT_FALSE(r.Fail(0, "third", "custom"));
  EXPECT_THAT(r.error(), HasSubstr("'first'"));
}

TEST(CdrReaderTest, RejectsInvalidBool) {
  const auto bytes = Bytes({0x00, 0x01, 0x00, 0x00, 0x02});
  CdrReader r(bytes);
  bool b = false;
  EXPECT_FALSE(r.ReadBool("flag", &b));
  EXPECT_EQ(r.error(), "field 'flag' at offset 4: invalid bool value 2 (expected 0 or 1)");
}

TEST(CdrReaderTest, RejectsStringLongerThanInput) {
  // Length 4000000 (0x003D0900) with only 3 bytes behind it.
  const auto bytes = Bytes({0x00, 0x01, 0x00, 0x00, 0x00, 0x09, 0x3D, 0x00, 'a', 'b', 0});
  CdrReader r(bytes, "pkg/msg/T");
  std::string s;
  EXPECT_FALSE(r.ReadString("name", &s));
  EXPECT_EQ(r.error(),
            "pkg/msg/T: field 'name' at offset 4: string length 4000000 exceeds remaining 3 "
            "bytes");
}

TEST(CdrReaderTest, RejectsStringWithoutNul) {
  const auto bytes = Bytes({0x00, 0x01, 0x00, 0x00, 0x02, 0x00, 0x00, 0x00, 'a', 'b'});
  CdrReader r(bytes);
  std::string_view s;
  EXPECT_FALSE(r.ReadStringView("name", &s));
  EXPECT_THAT(r.error(), HasSubstr("string of length 2 is not NUL-terminated"));
}

TEST(CdrReaderTest, AcceptsZeroLengthStringAsEmpty) {
  const auto bytes = Bytes({0x00, 0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00});
  CdrReader r(bytes);
  std::string s = "stale";
  EXPECT_TRUE(r.ReadString("name", &s));
  EXPECT_EQ(s, "");
}

TEST(CdrReaderTest, StringViewPointsIntoInput) {
  const auto bytes = Bytes({0x00, 0x01, 0x00, 0x00, 0x03, 0x00, 0x00, 0x00, 'h', 'i', 0});
  CdrReader r(bytes);
  std::string_view s;
  ASSERT_TRUE(r.ReadStringView("s", &s));
  EXPECT_EQ(s, "hi");
  EXPECT_EQ(static_cast<const void*>(s.data()), static_cast<const void*>(bytes.data() + 8));
}

TEST(CdrReaderTest, SequenceCountIsCappedByRemainingBytes) {
  // Count 0xFFFFFFFF with 4 bytes of data behind it: rejected before any
  // allocation is attempted.
  const auto bytes =
      Bytes({0x00, 0x01, 0x00, 0x00, 0xFF, 0xFF, 0xFF, 0xFF, 0x01, 0x02, 0x03, 0x04});
  {
    CdrReader r(bytes, "pkg/msg/T");
    std::vector<uint8_t> data;
    EXPECT_FALSE(r.ReadU8Sequence("data", &data));
    EXPECT_EQ(r.error(),
              "pkg/msg/T: field 'data' at offset 4: sequence length 4294967295 exceeds "
              "remaining 4 bytes");
    EXPECT_TRUE(data.empty());
  }
  {
    CdrReader r(bytes);
    size_t count = 0;
    EXPECT_FALSE(r.ReadSequenceSize("items", 8, &count));
    EXPECT_THAT(r.error(), HasSubstr("(elements take at least 8 bytes)"));
  }
  {
    const auto two = Bytes({0x00, 0x01, 0x00, 0x00, 0x02, 0x00, 0x00, 0x00, 0x01, 0x02, 0x03, 0x04,
                            0x05, 0x06, 0x07, 0x08});
    CdrReader r(two);
    size_t count = 0;
    EXPECT_TRUE(r.ReadSequenceSize("items", 4, &count));
    EXPECT_EQ(count, 2u);
  }
}

TEST(CdrReaderTest, NeverReadsPastTheSpan) {
  // Every prefix of a valid encoding must fail cleanly (ASan checks the reads:
  // each prefix is copied into an exactly sized heap block).
  std::vector<std::byte> full;
  {
    CdrWriter w(&full);
    w.WriteU8(1);
    w.WriteString("abcdef");
    w.WriteF64(2.0);
    w.WriteSequenceSize(2);
    const std::array<uint8_t, 2> octets = {5, 6};
    w.WriteU8Array(octets);
  }
  for (size_t n = 0; n < full.size(); ++n) {
    const std::vector<std::byte> prefix(full.begin(), full.begin() + static_cast<ptrdiff_t>(n));
    CdrReader r(prefix, "T");
    uint8_t u8 = 0;
    std::string s;
    double d = 0;
    std::vector<uint8_t> octets;
    const bool ok = r.ReadU8("a", &u8) && r.ReadString("b", &s) && r.ReadF64("c", &d) &&
                    r.ReadU8Sequence("d", &octets);
    EXPECT_FALSE(ok) << "prefix " << n;
    EXPECT_THAT(r.error(), HasSubstr("at offset ")) << "prefix " << n;
  }
}

}  // namespace
}  // namespace rover::log
