// Writing and reading back complete files.

#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "core/log/mcap/mcap_reader.h"
#include "core/log/mcap/mcap_writer.h"
#include "tests/core/log/mcap/mcap_test_util.h"
#include "tests/support/allocation_counter.h"

namespace rover::log {
namespace {

using testing::ReadAll;
using testing::TempDir;
using testing::TestLog;
using testing::TestMessage;
using testing::WriteTestLog;

class RoundTripTest : public ::testing::TestWithParam<Compression> {};

TEST_P(RoundTripTest, EverythingComesBackThroughTheSummary) {
  TempDir dir;
  const std::string path = dir.File("log.mcap").string();
  McapWriterOptions options;
  options.compression = GetParam();
  options.chunk_size_bytes = 8 << 10;  // Many chunks.
  const TestLog log = WriteTestLog(path, options, 600, 1);

  McapReader reader = McapReader::Open(path);
  EXPECT_TRUE(reader.summary_ok());
  EXPECT_FALSE(reader.truncated());
  EXPECT_TRUE(reader.damage().empty()) << testing::Describe(reader.damage());
  EXPECT_EQ(reader.header().profile, "ros2");
  EXPECT_EQ(reader.header().library, "rover_log");

  ASSERT_EQ(reader.schemas().size(), log.schemas.size());
  for (const Schema& s : log.schemas) EXPECT_EQ(reader.schemas().at(s.id), s);
  ASSERT_EQ(reader.channels().size(), log.channels.size());
  for (const Channel& c : log.channels) EXPECT_EQ(reader.channels().at(c.id), c);
  EXPECT_EQ(reader.metadata(), log.metadata);

  ASSERT_GT(reader.chunks().size(), 10U);
  uint64_t indexed_messages = 0;
  for (const ChunkInfo& chunk : reader.chunks()) {
    EXPECT_EQ(chunk.compression, CompressionName(GetParam()));
    indexed_messages += chunk.message_count;
  }
  EXPECT_EQ(indexed_messages, log.messages.size());

  ASSERT_TRUE(reader.statistics().has_value());
  const Statistics& stats = *reader.statistics();
  EXPECT_EQ(stats.message_count, log.messages.size());
  EXPECT_EQ(stats.schema_count, 2);
  EXPECT_EQ(stats.channel_count, 3U);
  EXPECT_EQ(stats.metadata_count, 1U);
  EXPECT_EQ(stats.attachment_count, 0U);
  EXPECT_EQ(stats.chunk_count, reader.chunks().size());
  EXPECT_EQ(stats.message_start_time, log.messages.front().log_time);
  EXPECT_EQ(stats.message_end_time, log.messages.back().log_time);
  for (const Channel& c : log.channels) {
    const auto n = std::count_if(log.messages.begin(), log.messages.end(),
                                 [&](const TestMessage& m) { return m.channel_id == c.id; });
    EXPECT_EQ(stats.channel_message_counts.at(c.id), static_cast<uint64_t>(n));
  }

  EXPECT_EQ(ReadAll(reader), log.messages);
  for (const ChunkInfo& chunk : reader.chunks()) EXPECT_EQ(chunk.status, ChunkStatus::kOk);

  // The linear scan finds the same.
  McapReader scanned = McapReader::Open(path, OpenOptions{.use_summary = false});
  EXPECT_FALSE(scanned.summary_ok());
  EXPECT_TRUE(scanned.damage().empty()) << testing::Describe(scanned.damage());
  EXPECT_EQ(scanned.chunks().size(), reader.chunks().size());
  EXPECT_EQ(ReadAll(scanned), log.messages);

  const VerifyReport report = Verify(path);
  EXPECT_TRUE(report.ok) << testing::Describe(report.damage);
  EXPECT_TRUE(report.summary_ok);
  EXPECT_EQ(report.message_count, log.messages.size());
  EXPECT_EQ(report.chunk_count, reader.chunks().size());
}

TEST_P(RoundTripTest, LogTimeOrderAndFilters) {
  TempDir dir;
  const std::string path = dir.File("log.mcap").string();
  McapWriterOptions options;
  options.compression = GetParam();
  options.chunk_size_bytes = 4 << 10;
  const TestLog log = WriteTestLog(path, options, 400, 2, /*shuffle_times=*/true);
  McapReader reader = McapReader::Open(path);

  std::vector<TestMessage> by_time = log.messages;
  std::stable_sort(by_time.begin(), by_time.end(), [](const TestMessage& a, const TestMessage& b) {
    return a.log_time < b.log_time;
  });
  ASSERT_NE(by_time, log.messages) << "the test needs out-of-order log times";
  ReadOptions by_log_time;
  by_log_time.order = ReadOptions::Order::kLogTime;
  EXPECT_EQ(ReadAll(reader, by_log_time), by_time);

  const uint64_t from = by_time[100].log_time;
  const uint64_t to = by_time[300].log_time;
  const uint16_t channel = log.channels[1].id;
  std::vector<TestMessage> want;
  for (const TestMessage& m : log.messages) {
    if (m.log_time >= from && m.log_time <= to && m.channel_id == channel) want.push_back(m);
  }
  ASSERT_FALSE(want.empty());
  ReadOptions filtered;
  filtered.start_time = from;
  filtered.end_time = to;
  filtered.channel_ids = {channel};
  EXPECT_EQ(ReadAll(reader, filtered), want);
  filtered.order = ReadOptions::Order::kLogTime;
  std::stable_sort(want.begin(), want.end(), [](const TestMessage& a, const TestMessage& b) {
    return a.log_time < b.log_time;
  });
  EXPECT_EQ(ReadAll(reader, filtered), want);

  // Stopping early.
  size_t seen = 0;
  reader.ForEachMessage([&](const MessageView&) { return ++seen < 10; });
  EXPECT_EQ(seen, 10U);
}

std::string CompressionTestName(const ::testing::TestParamInfo<Compression>& param) {
  const auto name = CompressionName(param.param);
  return name.empty() ? std::string("none") : std::string(name);
}

INSTANTIATE_TEST_SUITE_P(AllCompressions, RoundTripTest,
                         ::testing::Values(Compression::kNone, Compression::kZstd,
                                           Compression::kLz4),
                         CompressionTestName);

TEST(McapWriterTest, EmptyLogIsValid) {
  TempDir dir;
  const std::string path = dir.File("empty.mcap").string();
  {
    McapWriter writer;
    writer.Open(path);
  }  // The destructor closes.
  McapReader reader = McapReader::Open(path);
  EXPECT_TRUE(reader.summary_ok());
  EXPECT_TRUE(reader.chunks().empty());
  ASSERT_TRUE(reader.statistics().has_value());
  EXPECT_EQ(reader.statistics()->message_count, 0U);
  EXPECT_TRUE(ReadAll(reader).empty());
  EXPECT_TRUE(Verify(path).ok) << testing::Describe(Verify(path).damage);
}

TEST(McapWriterTest, ChunksCloseBySizeAndByDuration) {
  TempDir dir;
  McapWriterOptions options;
  options.chunk_size_bytes = 1 << 20;
  options.max_chunk_duration_ns = 500'000'000;
  const std::string path = dir.File("timed.mcap").string();
  McapWriter writer(options);
  writer.Open(path);
  const uint16_t channel = writer.AddChannel(0, "/tick", "raw");
  const std::vector<std::byte> payload(16, std::byte{1});
  for (uint32_t i = 0; i < 50; ++i) {
    writer.WriteMessage(channel, i, uint64_t{i} * 100'000'000, uint64_t{i} * 100'000'000, payload);
  }
  writer.Close();
  McapReader reader = McapReader::Open(path);
  ASSERT_EQ(reader.chunks().size(), 9U);  // 6 messages span 500 ms; 50 = 8 * 6 + 2.
  for (const ChunkInfo& chunk : reader.chunks()) {
    EXPECT_LE(chunk.message_end_time - chunk.message_start_time, 500'000'000U);
  }
  EXPECT_EQ(writer.stats().chunks, 9U);
  EXPECT_EQ(writer.stats().messages, 50U);

  // A tiny size limit puts every message in its own chunk.
  options.chunk_size_bytes = 1;
  options.sync_each_chunk = true;
  McapWriter small(options);
  small.Open(dir.File("small.mcap").string());
  const uint16_t c = small.AddChannel(0, "/tick", "raw");
  for (uint32_t i = 0; i < 5; ++i) small.WriteMessage(c, i, i, i, payload);
  small.Close();
  EXPECT_EQ(small.stats().chunks, 5U);
}

// The log thread writes continuously: once buffers have grown, a message that
// does not close a chunk must not touch the heap (closing one may, once).
TEST(McapWriterTest, SteadyStateWriteMessageDoesNotAllocate) {
  for (const Compression compression :
       {Compression::kNone, Compression::kZstd, Compression::kLz4}) {
    TempDir dir;
    McapWriterOptions options;
    options.compression = compression;
    options.chunk_size_bytes = 16 << 10;
    McapWriter writer(options);
    writer.Open(dir.File("steady.mcap").string());
    const uint16_t a = writer.AddChannel(0, "/a", "raw");
    const uint16_t b = writer.AddChannel(0, "/b", "raw");
    std::vector<std::byte> payload(200);
    for (size_t i = 0; i < payload.size(); ++i) payload[i] = static_cast<std::byte>(i * 13);
    uint64_t t = 0;
    for (uint32_t i = 0; i < 1000; ++i, t += 1000)
      writer.WriteMessage(i % 2 ? a : b, i, t, t, payload);

    uint64_t flushes = 0;
    uint64_t flush_allocations = 0;
    for (uint32_t i = 0; i < 2000; ++i, t += 1000) {
      const uint64_t chunks = writer.stats().chunks;
      const rover::testing::ScopedAllocationCheck check;
      writer.WriteMessage(i % 2 ? a : b, i, t, t, payload);
      if (writer.stats().chunks == chunks) {
        ASSERT_EQ(check.allocations(), 0U)
            << "message " << i << ", compression " << static_cast<int>(compression);
      } else {
        ++flushes;
        flush_allocations += check.allocations();
      }
    }
    EXPECT_GT(flushes, 10U);
    EXPECT_GT(flush_allocations, 0U);           // The counter works: chunk index entries allocate.
    EXPECT_LE(flush_allocations, 4 * flushes);  // The chunk index entry, not the data.
    writer.Close();
  }
}

TEST(McapWriterTest, IdsDeduplicationAndMisuse) {
  TempDir dir;
  McapWriter writer;
  EXPECT_THROW(writer.AddChannel(0, "/x", "raw"), McapError);  // Not open.
  writer.Open(dir.File("ids.mcap").string());
  EXPECT_THROW(writer.Open(dir.File("other.mcap").string()), McapError);
  const std::vector<std::byte> text(3, std::byte{'a'});
  const uint16_t s1 = writer.AddSchema("a/msg/A", "ros2msg", text);
  EXPECT_EQ(s1, 1);
  EXPECT_EQ(writer.AddSchema("a/msg/A", "ros2msg", text), s1);
  EXPECT_EQ(writer.AddSchema("a/msg/B", "ros2msg", text), 2);
  EXPECT_THROW(writer.AddSchemaWithId(2, "dup", "ros2msg", text), McapError);
  EXPECT_THROW(writer.AddSchemaWithId(0, "zero", "ros2msg", text), McapError);
  writer.AddSchemaWithId(7, "a/msg/C", "ros2msg", text);
  EXPECT_EQ(writer.AddSchema("a/msg/D", "ros2msg", text), 3);

  const uint16_t c1 = writer.AddChannel(s1, "/a", "cdr");
  EXPECT_EQ(c1, 1);
  EXPECT_EQ(writer.AddChannel(s1, "/a", "cdr"), c1);
  EXPECT_EQ(writer.AddChannel(s1, "/a", "cdr", {{"k", "v"}}), 2);
  EXPECT_THROW(writer.AddChannel(99, "/bad", "cdr"), McapError);
  EXPECT_THROW(writer.WriteMessage(42, 0, 0, 0, {}), McapError);
  writer.Close();
  writer.Close();  // Idempotent.
}

TEST(McapWriterTest, OpenFailureNamesThePath) {
  McapWriter writer;
  try {
    writer.Open("/nonexistent-dir/x.mcap");
    FAIL() << "expected McapError";
  } catch (const McapError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent-dir/x.mcap"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("No such file"), std::string::npos) << e.what();
  }
}

TEST(McapWriterTest, AttachmentsRoundTrip) {
  TempDir dir;
  const std::string path = dir.File("att.mcap").string();
  std::vector<std::byte> calib(1000);
  for (size_t i = 0; i < calib.size(); ++i) calib[i] = static_cast<std::byte>(i * 7);
  {
    McapWriter writer;
    writer.Open(path);
    writer.WriteAttachment("calib.yaml", "application/yaml", 5, 3, calib);
    const uint16_t c = writer.AddChannel(0, "/t", "raw");
    writer.WriteMessage(c, 0, 10, 10, calib);
    writer.Close();
    EXPECT_EQ(writer.stats().attachments, 1U);
  }
  for (const bool use_summary : {true, false}) {
    McapReader reader = McapReader::Open(path, OpenOptions{.use_summary = use_summary});
    ASSERT_EQ(reader.attachments().size(), 1U);
    const AttachmentInfo& info = reader.attachments()[0];
    EXPECT_EQ(info.name, "calib.yaml");
    EXPECT_EQ(info.media_type, "application/yaml");
    EXPECT_EQ(info.log_time, 5U);
    EXPECT_EQ(info.create_time, 3U);
    EXPECT_EQ(info.data_size, calib.size());
    EXPECT_EQ(reader.ReadAttachment(info), calib);
  }
  EXPECT_TRUE(Verify(path).ok);

  // A damaged attachment is reported, not returned, and Recover() leaves it out.
  std::vector<std::byte> bytes = testing::ReadFile(path);
  const AttachmentInfo info = McapReader::Open(path).attachments().at(0);
  bytes[info.offset + info.length - 10] ^= std::byte{0xFF};
  const std::string damaged = dir.File("damaged.mcap").string();
  testing::WriteFile(damaged, bytes);
  McapReader reader = McapReader::Open(damaged);
  EXPECT_FALSE(reader.ReadAttachment(reader.attachments().at(0)).has_value());
  ASSERT_EQ(reader.damage().size(), 1U);
  EXPECT_EQ(reader.damage()[0].offset, info.offset);
  EXPECT_NE(reader.damage()[0].what.find("CRC mismatch"), std::string::npos);
  const VerifyReport report = Verify(damaged);
  EXPECT_FALSE(report.ok);
  const RecoverResult result = Recover(damaged, dir.File("recovered.mcap").string());
  EXPECT_EQ(result.messages_written, 1U);
  EXPECT_TRUE(Verify(dir.File("recovered.mcap").string()).ok);
  EXPECT_TRUE(McapReader::Open(dir.File("recovered.mcap").string()).attachments().empty());
}

TEST(McapReaderTest, RejectsNonMcapInputClearly) {
  const std::string text = "this is not an mcap file at all";
  try {
    McapReader::Open(std::as_bytes(std::span(text)));
    FAIL() << "expected McapError";
  } catch (const McapError& e) {
    EXPECT_NE(std::string(e.what()).find("magic"), std::string::npos) << e.what();
  }
  EXPECT_THROW(McapReader::Open(std::span<const std::byte>()), McapError);
  EXPECT_THROW(McapReader::Open("/nonexistent-dir/x.mcap"), McapError);
  const VerifyReport report = Verify("/nonexistent-dir/x.mcap");
  EXPECT_FALSE(report.ok);
  ASSERT_EQ(report.damage.size(), 1U);
}

}  // namespace
}  // namespace rover::log
