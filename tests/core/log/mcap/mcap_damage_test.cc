// Truncated and corrupted files: the reader keeps everything intact, reports
// the rest with file offsets, and Verify()/Recover() agree with it.

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "core/log/mcap/mcap_reader.h"
#include "core/log/mcap/mcap_writer.h"
#include "tests/core/log/mcap/mcap_test_util.h"

namespace rover::log {
namespace {

using testing::Describe;
using testing::ReadAll;
using testing::ReadFile;
using testing::TempDir;
using testing::TestLog;
using testing::TestMessage;
using testing::WriteFile;
using testing::WriteTestLog;

// Magic (8) + Header record (9 + "ros2" + "rover_log" with length prefixes).
constexpr size_t kHeaderEnd = 8 + 9 + 4 + 4 + 4 + 9;

std::string CompressionTestName(const ::testing::TestParamInfo<Compression>& param) {
  const auto name = CompressionName(param.param);
  return name.empty() ? std::string("none") : std::string(name);
}

McapReader OpenBytes(const std::vector<std::byte>& bytes, size_t size) {
  return McapReader::Open(std::span(bytes).first(size));
}

bool HasDamageAt(const std::vector<Damage>& damage, uint64_t offset, const std::string& text) {
  return std::any_of(damage.begin(), damage.end(), [&](const Damage& d) {
    return d.offset == offset && d.what.find(text) != std::string::npos;
  });
}

class DamageTest : public ::testing::TestWithParam<Compression> {
 protected:
  void SetUp() override {
    McapWriterOptions options;
    options.compression = GetParam();
    options.chunk_size_bytes = 1500;
    path_ = dir_.File("log.mcap").string();
    log_ = WriteTestLog(path_, options, 220, 11);
    bytes_ = ReadFile(path_);
    McapReader reader = McapReader::Open(path_);
    chunks_ = reader.chunks();
    ASSERT_GT(chunks_.size(), 15U);
  }

  // The messages of the file minus those of chunk `k`.
  std::vector<TestMessage> AllBut(size_t k) const {
    uint64_t before = 0;
    for (size_t i = 0; i < k; ++i) before += chunks_[i].message_count;
    std::vector<TestMessage> out = log_.messages;
    out.erase(out.begin() + static_cast<ptrdiff_t>(before),
              out.begin() + static_cast<ptrdiff_t>(before + chunks_[k].message_count));
    return out;
  }

  // Writes `bytes`, recovers it, and checks the recovered file is clean and
  // holds exactly `expected`.
  RecoverResult RecoverAndCheck(const std::vector<std::byte>& bytes,
                                const std::vector<TestMessage>& expected) {
    const std::string damaged = dir_.File("damaged.mcap").string();
    const std::string recovered = dir_.File("recovered.mcap").string();
    WriteFile(damaged, bytes);
    McapWriterOptions options;
    options.compression = Compression::kZstd;
    const RecoverResult result = Recover(damaged, recovered, options);
    const VerifyReport report = Verify(recovered);
    EXPECT_TRUE(report.ok) << Describe(report.damage);
    EXPECT_EQ(report.message_count, expected.size());
    McapReader reader = McapReader::Open(recovered);
    EXPECT_TRUE(reader.summary_ok());
    EXPECT_EQ(ReadAll(reader), expected);
    EXPECT_EQ(reader.channels().size(), log_.channels.size());
    EXPECT_EQ(reader.schemas().size(), log_.schemas.size());
    EXPECT_EQ(reader.metadata(), log_.metadata);
    EXPECT_EQ(result.messages_written, expected.size());
    return result;
  }

  TempDir dir_;
  std::string path_;
  TestLog log_;
  std::vector<std::byte> bytes_;
  std::vector<ChunkInfo> chunks_;
};

TEST_P(DamageTest, EveryCutKeepsExactlyTheCompleteChunks) {
  std::set<size_t> cuts;
  for (size_t c = 0; c < std::min<size_t>(3072, bytes_.size()); ++c) cuts.insert(c);
  for (size_t c = 3072; c < bytes_.size(); c += 97) cuts.insert(c);
  for (const ChunkInfo& chunk : chunks_) {
    for (const uint64_t c : {chunk.offset, chunk.offset + 1, chunk.offset + chunk.length - 1,
                             chunk.offset + chunk.length, chunk.offset + chunk.length + 1}) {
      cuts.insert(static_cast<size_t>(c));
    }
  }
  cuts.insert(bytes_.size() - 1);

  for (const size_t cut : cuts) {
    SCOPED_TRACE("cut at " + std::to_string(cut) + " of " + std::to_string(bytes_.size()));
    if (cut < kHeaderEnd) {
      EXPECT_THROW(OpenBytes(bytes_, cut), McapError);
      continue;
    }
    McapReader reader = OpenBytes(bytes_, cut);
    EXPECT_TRUE(reader.truncated());
    EXPECT_FALSE(reader.summary_ok());
    EXPECT_FALSE(reader.damage().empty());
    uint64_t expected = 0;
    for (const ChunkInfo& chunk : chunks_) {
      if (chunk.offset + chunk.length <= cut) expected += chunk.message_count;
    }
    const std::vector<TestMessage> got = ReadAll(reader);
    ASSERT_EQ(got.size(), expected) << Describe(reader.damage());
    ASSERT_TRUE(std::equal(got.begin(), got.end(), log_.messages.begin()));
    if (cut >= chunks_[0].offset) {
      // Schema and channel records come first, before any chunk.
      EXPECT_EQ(reader.schemas().size(), log_.schemas.size());
      EXPECT_EQ(reader.channels().size(), log_.channels.size());
    }
  }
}

TEST_P(DamageTest, FlippedByteInChunkDropsOnlyThatChunk) {
  const size_t k = chunks_.size() / 2;
  const ChunkInfo& chunk = chunks_[k];
  std::vector<std::byte> bytes = bytes_;
  // Middle of the stored (compressed) records, which end where the record ends.
  bytes[chunk.offset + chunk.length - chunk.compressed_size / 2] ^= std::byte{0x5A};

  McapReader reader = OpenBytes(bytes, bytes.size());
  EXPECT_TRUE(reader.summary_ok());  // The summary itself is intact.
  EXPECT_EQ(ReadAll(reader), AllBut(k));
  ASSERT_EQ(reader.damage().size(), 1U) << Describe(reader.damage());
  EXPECT_TRUE(
      HasDamageAt(reader.damage(), chunk.offset, "chunk at offset " + std::to_string(chunk.offset)))
      << Describe(reader.damage());
  if (GetParam() == Compression::kNone) {
    EXPECT_TRUE(HasDamageAt(reader.damage(), chunk.offset, "uncompressed CRC mismatch"));
  }
  EXPECT_EQ(reader.chunks()[k].status, ChunkStatus::kDamaged);

  // Log-time order skips the same chunk.
  McapReader again = OpenBytes(bytes, bytes.size());
  ReadOptions by_log_time;
  by_log_time.order = ReadOptions::Order::kLogTime;
  EXPECT_EQ(ReadAll(again, by_log_time), AllBut(k));

  const VerifyReport report = Verify(std::span<const std::byte>(bytes));
  EXPECT_FALSE(report.ok);
  EXPECT_EQ(report.damaged_chunk_count, 1U);
  EXPECT_TRUE(HasDamageAt(report.damage, chunk.offset, "chunk at offset"));
  EXPECT_TRUE(std::any_of(report.damage.begin(), report.damage.end(), [](const Damage& d) {
    return d.what.find("data section CRC mismatch") != std::string::npos;
  })) << Describe(report.damage);

  const RecoverResult result = RecoverAndCheck(bytes, AllBut(k));
  EXPECT_EQ(result.chunks_dropped, 1U);
  EXPECT_EQ(result.chunks_recovered, chunks_.size() - 1);
  EXPECT_EQ(result.messages_dropped, chunk.message_count);
  EXPECT_FALSE(result.input_truncated);
}

TEST_P(DamageTest, FlippedByteInSummaryFallsBackToTheScan) {
  const uint64_t footer = bytes_.size() - 8 - 29;
  uint64_t summary_start = 0;
  for (int i = 7; i >= 0; --i) {
    summary_start =
        (summary_start << 8) | static_cast<uint64_t>(bytes_[footer + 9 + static_cast<size_t>(i)]);
  }
  std::vector<std::byte> bytes = bytes_;
  bytes[summary_start + 20] ^= std::byte{0x01};

  McapReader reader = OpenBytes(bytes, bytes.size());
  EXPECT_FALSE(reader.summary_ok());
  EXPECT_FALSE(reader.truncated());
  EXPECT_FALSE(reader.statistics().has_value());
  EXPECT_TRUE(HasDamageAt(reader.damage(), summary_start, "summary: CRC mismatch"))
      << Describe(reader.damage());
  EXPECT_EQ(reader.chunks().size(), chunks_.size());
  EXPECT_EQ(ReadAll(reader), log_.messages);

  const VerifyReport report = Verify(std::span<const std::byte>(bytes));
  EXPECT_FALSE(report.ok);
  EXPECT_FALSE(report.summary_ok);
  EXPECT_EQ(report.message_count, log_.messages.size());

  const RecoverResult result = RecoverAndCheck(bytes, log_.messages);
  EXPECT_EQ(result.chunks_dropped, 0U);
}

TEST_P(DamageTest, CorruptChunkLengthIsSkippedByResynchronising) {
  const size_t k = chunks_.size() / 3;
  std::vector<std::byte> bytes = bytes_;
  bytes[chunks_[k].offset + 8] = std::byte{0x7F};  // Top byte of the record length.

  McapReader reader = OpenBytes(bytes, bytes.size());
  EXPECT_FALSE(reader.summary_ok());  // The chunk index no longer matches the record.
  EXPECT_EQ(ReadAll(reader), AllBut(k)) << Describe(reader.damage());
  EXPECT_TRUE(HasDamageAt(reader.damage(), chunks_[k].offset, "resynchron") ||
              HasDamageAt(reader.damage(), chunks_[k].offset, "skipped"))
      << Describe(reader.damage());
  RecoverAndCheck(bytes, AllBut(k));
}

TEST_P(DamageTest, TruncatedFileIsRecoveredUpToItsLastChunk) {
  const size_t k = chunks_.size() - 3;
  const size_t cut = static_cast<size_t>(chunks_[k].offset + chunks_[k].length / 2);
  std::vector<std::byte> bytes(bytes_.begin(), bytes_.begin() + static_cast<ptrdiff_t>(cut));
  std::vector<TestMessage> expected = log_.messages;
  uint64_t keep = 0;
  for (size_t i = 0; i < k; ++i) keep += chunks_[i].message_count;
  expected.resize(keep);

  const VerifyReport report = Verify(std::span<const std::byte>(bytes));
  EXPECT_FALSE(report.ok);
  EXPECT_TRUE(report.truncated);
  EXPECT_EQ(report.message_count, keep);

  const RecoverResult result = RecoverAndCheck(bytes, expected);
  EXPECT_TRUE(result.input_truncated);
  EXPECT_EQ(result.chunks_recovered, k);
}

// Seeded random damage of small files: never crashes, never leaks past its
// bounds (ASan), and with one flipped byte never delivers altered content.
TEST_P(DamageTest, RandomMutationsNeverCrashOrDeliverAlteredMessages) {
  const std::set<std::vector<std::byte>> originals = [&] {
    std::set<std::vector<std::byte>> s;
    for (const TestMessage& m : log_.messages) s.insert(m.data);
    return s;
  }();
  std::mt19937 rng(99);
  for (int iteration = 0; iteration < 300; ++iteration) {
    std::vector<std::byte> bytes = bytes_;
    const int flips = iteration % 3 == 0 ? 1 + static_cast<int>(rng() % 8) : 1;
    for (int f = 0; f < flips; ++f) {
      bytes[rng() % bytes.size()] = static_cast<std::byte>(rng() & 0xFFU);
    }
    if (iteration % 5 == 0) bytes.resize(rng() % bytes.size());
    try {
      McapReader reader = OpenBytes(bytes, bytes.size());
      for (const auto order : {ReadOptions::Order::kFile, ReadOptions::Order::kLogTime}) {
        ReadOptions read_options;
        read_options.order = order;
        reader.ForEachMessage(
            [&](const MessageView& m) {
              if (flips == 1) {
                EXPECT_TRUE(
                    originals.contains(std::vector<std::byte>(m.data.begin(), m.data.end())))
                    << "iteration " << iteration << " delivered altered data";
              }
              return true;
            },
            read_options);
      }
      (void)reader.Verify();
    } catch (const McapError&) {
      // Only a damaged magic or header may throw.
    }
  }
}

INSTANTIATE_TEST_SUITE_P(AllCompressions, DamageTest,
                         ::testing::Values(Compression::kNone, Compression::kZstd,
                                           Compression::kLz4),
                         CompressionTestName);

}  // namespace
}  // namespace rover::log
