// Byte-exact layout of a tiny uncompressed file, built independently of the
// library's serialisers from the MCAP specification.

#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <string_view>
#include <vector>

#include "core/log/mcap/mcap_writer.h"
#include "tests/core/log/mcap/mcap_test_util.h"

namespace rover::log {
namespace {

// Bit-at-a-time CRC-32 from the definition, so the test does not trust the library's.
uint32_t ReferenceCrc32(const std::vector<uint8_t>& data, size_t begin, size_t end) {
  uint32_t c = 0xFFFFFFFFU;
  for (size_t i = begin; i < end; ++i) {
    c ^= data[i];
    for (int bit = 0; bit < 8; ++bit) c = (c & 1U) != 0 ? (c >> 1) ^ 0xEDB88320U : c >> 1;
  }
  return ~c;
}

// Little-endian byte builder for the expected file.
struct Bytes {
  std::vector<uint8_t> b;
  void u8(uint64_t v) { b.push_back(static_cast<uint8_t>(v)); }
  void u16(uint64_t v) { le(v, 2); }
  void u32(uint64_t v) { le(v, 4); }
  void u64(uint64_t v) { le(v, 8); }
  void le(uint64_t v, int n) {
    for (int i = 0; i < n; ++i) b.push_back(static_cast<uint8_t>(v >> (8 * i)));
  }
  void raw(std::string_view s) { b.insert(b.end(), s.begin(), s.end()); }
  void str(std::string_view s) {
    u32(s.size());
    raw(s);
  }
  // Opcode + uint64 length of a record whose body has `n` bytes.
  void rec(uint8_t op, uint64_t n) {
    u8(op);
    u64(n);
  }
  size_t size() const { return b.size(); }
};

TEST(McapLayoutTest, TinyUncompressedFileIsByteExact) {
  testing::TempDir dir;
  const std::string path = dir.File("tiny.mcap").string();
  McapWriterOptions options;
  options.compression = Compression::kNone;
  {
    McapWriter writer(options);
    writer.Open(path);
    const std::string abc = "abc";
    const uint16_t schema = writer.AddSchema("s", "ros2msg", std::as_bytes(std::span(abc)));
    const uint16_t channel = writer.AddChannel(schema, "/t", "cdr", {{"k", "v"}});
    writer.WriteMetadata("m", {{"a", "b"}});
    const std::byte payload[] = {std::byte{1}, std::byte{2}, std::byte{3}};
    writer.WriteMessage(channel, 7, 100, 99, payload);
    writer.WriteMessage(channel, 8, 200, 199, {});
    writer.Close();
  }

  Bytes x;
  const std::string_view magic("\x89MCAP0\r\n", 8);
  x.raw(magic);
  x.rec(0x01, 4 + 4 + 4 + 9);  // Header
  x.str("ros2");
  x.str("rover_log");
  ASSERT_EQ(x.size(), 38U);

  const auto schema = [&] {
    x.rec(0x03, 2 + 5 + 11 + 7);
    x.u16(1);
    x.str("s");
    x.str("ros2msg");
    x.u32(3);
    x.raw("abc");
  };
  const auto channel = [&] {
    x.rec(0x04, 2 + 2 + 6 + 7 + 14);
    x.u16(1);
    x.u16(1);
    x.str("/t");
    x.str("cdr");
    x.u32(10);  // Map byte length: "k" and "v" with their length prefixes.
    x.str("k");
    x.str("v");
  };
  schema();
  channel();
  const size_t metadata_at = x.size();
  x.rec(0x0C, 5 + 14);
  x.str("m");
  x.u32(10);
  x.str("a");
  x.str("b");
  ASSERT_EQ(metadata_at, 112U);

  // Chunk records: two Message records.
  Bytes records;
  records.rec(0x05, 22 + 3);
  records.u16(1);
  records.u32(7);
  records.u64(100);
  records.u64(99);
  records.u8(1);
  records.u8(2);
  records.u8(3);
  const size_t second_message = records.size();
  records.rec(0x05, 22);
  records.u16(1);
  records.u32(8);
  records.u64(200);
  records.u64(199);
  ASSERT_EQ(records.size(), 65U);

  const size_t chunk_at = x.size();
  ASSERT_EQ(chunk_at, 140U);
  x.rec(0x06, 8 + 8 + 8 + 4 + 4 + 8 + records.size());
  x.u64(100);  // message_start_time
  x.u64(200);  // message_end_time
  x.u64(records.size());
  x.u32(ReferenceCrc32(records.b, 0, records.size()));
  x.str("");  // No compression.
  x.u64(records.size());
  x.b.insert(x.b.end(), records.b.begin(), records.b.end());
  const size_t chunk_length = x.size() - chunk_at;
  ASSERT_EQ(chunk_length, 114U);

  const size_t message_index_at = x.size();
  x.rec(0x07, 2 + 4 + 32);
  x.u16(1);
  x.u32(32);
  x.u64(100);
  x.u64(0);
  x.u64(200);
  x.u64(second_message);
  const size_t message_index_length = x.size() - message_index_at;

  const size_t data_end_at = x.size();
  ASSERT_EQ(data_end_at, 301U);
  x.rec(0x0F, 4);
  x.u32(ReferenceCrc32(x.b, 0, data_end_at));  // Covers the magic and everything up to here.

  const size_t summary_start = x.size();
  ASSERT_EQ(summary_start, 314U);
  schema();
  channel();
  const size_t statistics_at = x.size();
  x.rec(0x0B, 8 + 2 + 4 + 4 + 4 + 4 + 8 + 8 + 4 + 10);
  x.u64(2);  // message_count
  x.u16(1);  // schema_count
  x.u32(1);  // channel_count
  x.u32(0);  // attachment_count
  x.u32(1);  // metadata_count
  x.u32(1);  // chunk_count
  x.u64(100);
  x.u64(200);
  x.u32(10);  // channel_message_counts: {1: 2}
  x.u16(1);
  x.u64(2);
  const size_t chunk_index_at = x.size();
  x.rec(0x08, 8 + 8 + 8 + 8 + 14 + 8 + 4 + 8 + 8);
  x.u64(100);
  x.u64(200);
  x.u64(chunk_at);
  x.u64(chunk_length);
  x.u32(10);  // message_index_offsets: {1: offset}
  x.u16(1);
  x.u64(message_index_at);
  x.u64(message_index_length);
  x.str("");
  x.u64(records.size());  // compressed_size
  x.u64(records.size());  // uncompressed_size
  const size_t metadata_index_at = x.size();
  x.rec(0x0D, 8 + 8 + 5);
  x.u64(metadata_at);
  x.u64(28);
  x.str("m");

  const size_t summary_offset_start = x.size();
  ASSERT_EQ(summary_offset_start, 566U);
  const auto group = [&](uint8_t op, size_t start, size_t end) {
    x.rec(0x0E, 17);
    x.u8(op);
    x.u64(start);
    x.u64(end - start);
  };
  group(0x03, summary_start, summary_start + 34);
  group(0x04, summary_start + 34, statistics_at);
  group(0x0B, statistics_at, chunk_index_at);
  group(0x08, chunk_index_at, metadata_index_at);
  group(0x0D, metadata_index_at, summary_offset_start);

  const size_t footer_at = x.size();
  x.rec(0x02, 20);
  x.u64(summary_start);
  x.u64(summary_offset_start);
  // From the summary start through the footer's summary_offset_start field.
  x.u32(ReferenceCrc32(x.b, summary_start, x.size()));
  x.raw(magic);
  ASSERT_EQ(footer_at, 696U);
  ASSERT_EQ(x.size(), 733U);

  const std::vector<std::byte> file = testing::ReadFile(path);
  ASSERT_EQ(file.size(), x.size());
  for (size_t i = 0; i < file.size(); ++i) {
    ASSERT_EQ(static_cast<uint8_t>(file[i]), x.b[i]) << "first difference at byte " << i;
  }
}

}  // namespace
}  // namespace rover::log
