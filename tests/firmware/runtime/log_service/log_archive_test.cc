// core/log/archive: SHA-256, log names, the listing JSON and the servable
// length of MCAP files (complete, being written, cut at every byte).

#include <fcntl.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "core/log/archive/log_listing.h"
#include "core/log/archive/log_name.h"
#include "core/log/archive/mcap_servable.h"
#include "core/log/archive/sha256.h"
#include "core/log/mcap/mcap_reader.h"
#include "tests/firmware/runtime/log_service/log_test_util.h"
#include "tests/support/temp_dir.h"

namespace rover::log {
namespace {

using runtime::testing::CoreutilsSha256;
using runtime::testing::MessageTimeNs;
using runtime::testing::ReadBytes;
using runtime::testing::TestLogWriter;
using runtime::testing::WriteBytes;
using runtime::testing::WriteCompleteLog;
using ::testing::HasSubstr;

// --- SHA-256 -------------------------------------------------------------------

TEST(Sha256Test, MatchesFips180Vectors) {
  EXPECT_EQ(Sha256Hex({}), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  Sha256 abc;
  abc.Update(std::string_view("abc"));
  EXPECT_EQ(abc.HexDigest(), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  Sha256 two_blocks;
  two_blocks.Update(std::string_view("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"));
  EXPECT_EQ(two_blocks.HexDigest(),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  Sha256 million_a;
  const std::string thousand(1000, 'a');
  for (int i = 0; i < 1000; ++i) million_a.Update(thousand);
  EXPECT_EQ(million_a.HexDigest(),
            "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
  EXPECT_EQ(million_a.size_bytes(), 1'000'000U);
}

TEST(Sha256Test, DigestLeavesStateAndCopiesContinueIndependently) {
  Sha256 sha;
  sha.Update(std::string_view("ab"));
  const std::string ab = sha.HexDigest();
  Sha256 copy = sha;
  sha.Update(std::string_view("c"));
  EXPECT_EQ(sha.HexDigest(), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(copy.HexDigest(), ab);
  copy = sha;
  EXPECT_EQ(copy.HexDigest(), sha.HexDigest());
}

TEST(Sha256Test, FileHashesAgreeWithCoreutils) {
  testing::TempDir dir("sha");
  const std::string path = dir.File("a.mcap").string();
  WriteCompleteLog(path, 40, 7);
  EXPECT_EQ(Sha256FileHex(path), CoreutilsSha256(path));
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  ASSERT_GE(fd, 0);
  Sha256 prefix;
  Sha256UpdateFromFile(fd, 0, 1000, path, &prefix);
  EXPECT_EQ(prefix.HexDigest(), CoreutilsSha256(path, 1000));
  Sha256UpdateFromFile(fd, 1000, 12345, path, &prefix);
  EXPECT_EQ(prefix.HexDigest(), CoreutilsSha256(path, 13345));
  const auto size = std::filesystem::file_size(path);
  EXPECT_THAT([&] { Sha256UpdateFromFile(fd, 0, size + 1, path, &prefix); },
              ::testing::ThrowsMessage<std::runtime_error>(HasSubstr("found the file ends at")));
  ::close(fd);
}

TEST(Sha256Test, ConstantTimeEqualsComparesContent) {
  EXPECT_TRUE(ConstantTimeEquals("token", "token"));
  EXPECT_FALSE(ConstantTimeEquals("token", "tokem"));
  EXPECT_FALSE(ConstantTimeEquals("token", "token2"));
  EXPECT_FALSE(ConstantTimeEquals("", "x"));
  EXPECT_TRUE(ConstantTimeEquals("", ""));
}

// --- names ---------------------------------------------------------------------

TEST(LogNameTest, AcceptsPlainMcapNames) {
  for (const char* name : {"flight_0001.mcap", "a.mcap", "2024-05-01.run-3.mcap", "_x.mcap"}) {
    EXPECT_TRUE(IsValidLogName(name)) << name;
  }
}

TEST(LogNameTest, RefusesPathsAndOddNamesSayingWhy) {
  const std::string nul_name("a\0b.mcap", 8);
  for (const std::string& name :
       {std::string(""), std::string("../../etc/passwd"), std::string("/etc/passwd.mcap"),
        std::string("..mcap"), std::string("a..b.mcap"), std::string(".hidden.mcap"),
        std::string("-rf.mcap"), std::string("x/y.mcap"), std::string("%2e%2e%2fx.mcap"),
        std::string("a b.mcap"), nul_name, std::string("log.txt"), std::string(".mcap"),
        std::string("log.mcap.part"), std::string(300, 'a') + ".mcap"}) {
    std::string why;
    EXPECT_FALSE(IsValidLogName(name, &why)) << name;
    EXPECT_THAT(why, HasSubstr("expected")) << name;
    EXPECT_THAT(why, HasSubstr("found")) << name;
  }
  std::string why;
  IsValidLogName(nul_name, &why);
  EXPECT_THAT(why, HasSubstr("byte 0x00 at position 1"));
}

// --- listing JSON ----------------------------------------------------------------

TEST(LogListingTest, RoundTripsEntries) {
  const std::vector<LogListingEntry> entries = {{.name = "a.mcap",
                                                 .size_bytes = 123,
                                                 .start_time_ns = 1,
                                                 .end_time_ns = 18446744073709551615ULL,
                                                 .sha256 = std::string(64, 'a'),
                                                 .complete = true},
                                                {.name = "b.mcap",
                                                 .size_bytes = 0,
                                                 .start_time_ns = std::nullopt,
                                                 .end_time_ns = std::nullopt,
                                                 .sha256 = std::string(64, '0'),
                                                 .complete = false}};
  const std::string json = LogListingToJson(entries);
  EXPECT_THAT(json, HasSubstr("\"start_time_ns\": null"));
  EXPECT_EQ(ParseLogListingJson(json), entries);
  EXPECT_TRUE(ParseLogListingJson(LogListingToJson({})).empty());
}

TEST(LogListingTest, SkipsUnknownKeysAndAcceptsEscapes) {
  const std::string sha(64, 'f');
  const auto entries = ParseLogListingJson(
      "[ {\"extra\": {\"x\": [1, 2.5e3, -4, true, null, \"s\\u00e9\\ud83d\\ude00\"]},\n"
      "   \"na\\u006de\": \"x.mcap\", \"size_bytes\": 7, \"sha256\": \"" +
      sha + "\", \"complete\": false} ]");
  ASSERT_EQ(entries.size(), 1U);
  EXPECT_EQ(entries[0].name, "x.mcap");
  EXPECT_EQ(entries[0].size_bytes, 7U);
  EXPECT_FALSE(entries[0].start_time_ns);
}

TEST(LogListingTest, ErrorsSayWhatWasExpectedWhereAndWhatWasFound) {
  const std::string sha(64, 'a');
  const auto error_of = [](const std::string& json) {
    try {
      ParseLogListingJson(json);
    } catch (const LogListingError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_THAT(error_of("{}"), HasSubstr("expected '[' starting the listing array at offset 0, "
                                        "found '{'"));
  EXPECT_THAT(error_of("[{\"name\": \"../x.mcap\", \"size_bytes\": 1, \"sha256\": \"" + sha +
                       "\", \"complete\": true}]"),
              HasSubstr("expected a valid log name"));
  EXPECT_THAT(error_of("[{\"name\": \"x.mcap\", \"size_bytes\": -1}]"),
              HasSubstr("expected size_bytes as a non-negative integer at offset 34, found '-'"));
  EXPECT_THAT(error_of("[{\"name\": \"x.mcap\", \"size_bytes\": 99999999999999999999}]"),
              HasSubstr("size_bytes within 0..18446744073709551615"));
  EXPECT_THAT(error_of("[{\"name\": \"x.mcap\", \"size_bytes\": 1, \"complete\": true}]"),
              HasSubstr("expected the key \"sha256\""));
  EXPECT_THAT(error_of("[{\"name\": \"x.mcap\", \"sha256\": \"ABC\"}]"),
              HasSubstr("sha256 as 64 lowercase hex characters"));
  EXPECT_THAT(error_of("[] x"), HasSubstr("expected the end of the listing"));
  EXPECT_THAT(error_of("[{\"name\": \"x.mcap"), HasSubstr("found the end of the text"));
  EXPECT_THAT(error_of("[{\"x\": " + std::string(40, '[') + std::string(40, ']') + "}]"),
              HasSubstr("nested at most 32 deep"));
}

// --- servable length -------------------------------------------------------------

McapServableInfo Examine(const std::string& path, McapServableTracker& tracker) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  EXPECT_GE(fd, 0) << path;
  McapServableInfo info = tracker.Update(fd, path);
  ::close(fd);
  return info;
}

TEST(McapServableTest, CompleteLogIsServedWholeWithSummaryTimes) {
  testing::TempDir dir("servable");
  const std::string path = dir.File("c.mcap").string();
  WriteCompleteLog(path, 50, 8);
  McapServableTracker tracker;
  const McapServableInfo info = Examine(path, tracker);
  EXPECT_TRUE(info.complete);
  EXPECT_EQ(info.servable_length_bytes, std::filesystem::file_size(path));
  EXPECT_EQ(info.start_time_ns, MessageTimeNs(0));
  EXPECT_EQ(info.end_time_ns, MessageTimeNs(49));
  EXPECT_EQ(info.sha256, CoreutilsSha256(path));
}

TEST(McapServableTest, LogBeingWrittenGrowsChunkByChunkThenCompletes) {
  testing::TempDir dir("servable");
  const std::string path = dir.File("live.mcap").string();
  TestLogWriter writer(path);
  McapServableTracker tracker;
  McapServableInfo info = Examine(path, tracker);  // magic + header only
  EXPECT_FALSE(info.complete);
  EXPECT_EQ(info.servable_length_bytes, writer.bytes_written());
  EXPECT_FALSE(info.start_time_ns);

  int next = 0;
  for (int round = 0; round < 3; ++round) {
    writer.Write(next, 10);
    next += 10;
    writer.FlushChunk();
    writer.Write(next, 3);  // buffered in the open chunk, not on disk yet
    next += 3;
    info = Examine(path, tracker);
    EXPECT_FALSE(info.complete);
    EXPECT_EQ(info.servable_length_bytes, writer.bytes_written());
    EXPECT_EQ(info.start_time_ns, MessageTimeNs(0));
    EXPECT_EQ(info.end_time_ns, MessageTimeNs(next - 4));
    EXPECT_EQ(info.sha256, CoreutilsSha256(path, info.servable_length_bytes));
    writer.FlushChunk();
  }
  writer.Close();
  info = Examine(path, tracker);
  EXPECT_TRUE(info.complete);
  EXPECT_EQ(info.servable_length_bytes, std::filesystem::file_size(path));
  EXPECT_EQ(info.sha256, CoreutilsSha256(path));
}

TEST(McapServableTest, CutAtEveryByteServesOnlyCompleteRecordsThatTheReaderAccepts) {
  testing::TempDir dir("servable");
  const std::string full = dir.File("full.mcap").string();
  WriteCompleteLog(full, 12, 4, 40);
  const std::vector<std::byte> bytes = ReadBytes(full);
  // Record ends of the data section, from an independent walk with the reader.
  const McapReader reader = McapReader::Open(full, OpenOptions{.use_summary = false});
  std::vector<uint64_t> chunk_ends;
  for (const ChunkInfo& c : reader.chunks()) chunk_ends.push_back(c.offset + c.length);
  ASSERT_EQ(chunk_ends.size(), 3U);

  const std::string cut = dir.File("cut.mcap").string();
  uint64_t previous = 0;
  for (size_t n = 0; n < bytes.size(); ++n) {
    WriteBytes(cut,
               std::vector<std::byte>(bytes.begin(), bytes.begin() + static_cast<ptrdiff_t>(n)));
    McapServableTracker tracker;
    const McapServableInfo info = Examine(cut, tracker);
    ASSERT_LE(info.servable_length_bytes, n);
    ASSERT_GE(info.servable_length_bytes, previous) << "servable length shrank at cut " << n;
    previous = info.servable_length_bytes;
    ASSERT_FALSE(info.complete) << n;
    // Every complete chunk record before the cut is servable.
    uint64_t chunks_before = 0;
    for (const uint64_t end : chunk_ends) chunks_before += end <= n ? 1 : 0;
    if (info.servable_length_bytes == 0) continue;
    const std::vector<std::byte> served(
        bytes.begin(), bytes.begin() + static_cast<ptrdiff_t>(info.servable_length_bytes));
    McapReader prefix = McapReader::Open(served);
    uint64_t messages = 0;
    prefix.ForEachMessage([&](const MessageView&) {
      ++messages;
      return true;
    });
    ASSERT_EQ(messages, 4 * chunks_before) << "cut at " << n;
    for (const Damage& d : prefix.damage()) {
      ASSERT_THAT(d.what, ::testing::Not(HasSubstr("CRC"))) << "cut at " << n;
    }
  }
}

TEST(McapServableTest, ReplacedOrRewrittenFileIsExaminedAgain) {
  testing::TempDir dir("servable");
  const std::string path = dir.File("r.mcap").string();
  WriteCompleteLog(path, 30, 10);
  McapServableTracker tracker;
  const McapServableInfo first = Examine(path, tracker);
  // Rewrite in place (same inode), longer and with other payloads.
  WriteCompleteLog(path, 40, 10, 2100);
  const McapServableInfo second = Examine(path, tracker);
  EXPECT_NE(second.sha256, first.sha256);
  EXPECT_EQ(second.sha256, CoreutilsSha256(path));
  EXPECT_EQ(second.end_time_ns, MessageTimeNs(39));
  // Not MCAP at all: nothing servable.
  std::filesystem::remove(path);
  WriteBytes(path, std::vector<std::byte>(100, std::byte{'x'}));
  const McapServableInfo third = Examine(path, tracker);
  EXPECT_EQ(third.servable_length_bytes, 0U);
  EXPECT_EQ(third.sha256, Sha256Hex({}));
}

}  // namespace
}  // namespace rover::log
