// `rover-log list` and `rover-log download` against a real log service on
// 127.0.0.1: table and JSON, resume after a cut connection with a Range
// request, SHA-256 verification, nothing under the final name until verified.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <mutex>
#include <optional>
#include <sstream>
#include <vector>

#include "core/log/archive/log_listing.h"
#include "core/log/mcap/mcap_reader.h"
#include "firmware/runtime/log_service/log_service.h"
#include "host/log/commands.h"
#include "tests/firmware/runtime/log_service/log_test_util.h"
#include "tests/support/temp_dir.h"

namespace rover::host {
namespace {

namespace fs = std::filesystem;
using runtime::LogService;
using runtime::LogServiceHooks;
using runtime::testing::CoreutilsSha256;
using runtime::testing::kToken;
using runtime::testing::ReadBytes;
using runtime::testing::ReadText;
using runtime::testing::TestLogWriter;
using runtime::testing::TestOptions;
using runtime::testing::WriteCompleteLog;
using ::testing::HasSubstr;
using ::testing::Not;

// Cuts transfers, as a broken link would: the service's before_send hook.
class TransferCutter {
 public:
  // Cut the next transfer before it sends the bytes at or after `offset`.
  void CutOnceAt(uint64_t offset) {
    std::lock_guard lock(mutex_);
    cut_at_ = offset;
  }
  // Cut every transfer before its first byte.
  void CutAlways() {
    std::lock_guard lock(mutex_);
    cut_always_ = true;
  }
  bool BeforeSend(uint64_t offset) {
    std::lock_guard lock(mutex_);
    if (cut_always_) return false;
    if (cut_at_ && offset >= *cut_at_) {
      cut_at_.reset();
      cut_offsets_.push_back(offset);
      return false;
    }
    return true;
  }
  std::vector<uint64_t> cut_offsets() const {
    std::lock_guard lock(mutex_);
    return cut_offsets_;
  }

 private:
  mutable std::mutex mutex_;
  std::optional<uint64_t> cut_at_;
  bool cut_always_ = false;
  std::vector<uint64_t> cut_offsets_;
};

class LogDownloadTest : public ::testing::Test {
 protected:
  void SetUp() override { fs::create_directories(folder_); }

  void StartService(LogServiceHooks hooks = {}) {
    service_ = std::make_unique<LogService>(TestOptions(folder_.string()), std::move(hooks));
    service_->Start();
  }

  LogServiceAccess Access(const std::string& token = kToken) const {
    LogServiceAccess access;
    access.url = "http://127.0.0.1:" + std::to_string(service_->port());
    access.token = token;
    return access;
  }

  DownloadOptions Download(const std::string& name) const {
    DownloadOptions options;
    options.access = Access();
    options.name = name;
    options.out_dir = out_.string();
    options.initial_backoff_s = 0.0;
    options.max_backoff_s = 0.0;
    return options;
  }

  std::string LogPath(const std::string& name) const { return (folder_ / name).string(); }

  testing::TempDir dir_{"log_download"};
  fs::path folder_ = dir_.path() / "board";
  fs::path out_ = dir_.path() / "host";
  std::unique_ptr<LogService> service_;
  std::ostringstream out_text_, err_text_;
};

TEST_F(LogDownloadTest, DownloadsAndVerifiesACompleteLog) {
  WriteCompleteLog(LogPath("flight.mcap"), 50, 10);
  StartService();
  bool verified_before_rename = false;
  DownloadOptions options = Download("flight.mcap");
  options.hooks.before_verify = [&](const std::string& part) {
    verified_before_rename = fs::exists(part) && !fs::exists(out_ / "flight.mcap");
  };
  ASSERT_EQ(RunDownload(options, out_text_, err_text_), 0) << err_text_.str();
  EXPECT_TRUE(verified_before_rename);
  EXPECT_EQ(ReadBytes((out_ / "flight.mcap").string()), ReadBytes(LogPath("flight.mcap")));
  EXPECT_FALSE(fs::exists(out_ / "flight.mcap.part"));
  EXPECT_THAT(out_text_.str(), HasSubstr(CoreutilsSha256(LogPath("flight.mcap")) + " verified"));
  // Not a terminal: a progress line at every 10 %, with rate and ETA.
  EXPECT_THAT(err_text_.str(), HasSubstr("flight.mcap: 100.0 %"));
  EXPECT_THAT(err_text_.str(), HasSubstr("/s, ETA"));
}

TEST_F(LogDownloadTest, CutConnectionResumesWithARangeRequestAndVerifies) {
  WriteCompleteLog(LogPath("cut.mcap"), 200, 20);  // ~400 KiB: several 64 KiB chunks
  const uint64_t size = fs::file_size(LogPath("cut.mcap"));
  TransferCutter transfers;
  transfers.CutOnceAt(size / 2);
  StartService({.before_send = [&](const std::string&, uint64_t offset) {
    return transfers.BeforeSend(offset);
  }});

  DownloadOptions options = Download("cut.mcap");
  uint64_t part_size_at_verify = 0;
  bool final_absent_at_verify = false;
  options.hooks.before_verify = [&](const std::string& part) {
    part_size_at_verify = fs::file_size(part);
    final_absent_at_verify = !fs::exists(out_ / "cut.mcap");
  };
  ASSERT_EQ(RunDownload(options, out_text_, err_text_), 0) << err_text_.str();

  const std::vector<uint64_t> cuts = transfers.cut_offsets();
  ASSERT_EQ(cuts.size(), 1U);
  EXPECT_GT(cuts[0], 0U);
  EXPECT_LT(cuts[0], size);
  // The second request asked for exactly the bytes after the cut.
  EXPECT_THAT(err_text_.str(), HasSubstr("transfer interrupted at byte " + std::to_string(cuts[0]) +
                                         " of " + std::to_string(size)));
  EXPECT_THAT(err_text_.str(), HasSubstr("resuming with a Range request"));
  EXPECT_EQ(part_size_at_verify, size);
  EXPECT_TRUE(final_absent_at_verify);
  EXPECT_EQ(ReadBytes((out_ / "cut.mcap").string()), ReadBytes(LogPath("cut.mcap")));
  EXPECT_FALSE(fs::exists(out_ / "cut.mcap.part"));
  service_->Stop();
  const auto counters = service_->counters();
  EXPECT_EQ(counters.transfers_started, 2U);
  EXPECT_EQ(counters.transfers_aborted, 1U);
  EXPECT_EQ(counters.transfers_completed, 1U);
  EXPECT_EQ(counters.partial_responses, 2U);  // both requests carry a Range
  EXPECT_EQ(counters.bytes_served, size);     // nothing was sent twice
}

TEST_F(LogDownloadTest, LeftoverPartFileIsResumed) {
  WriteCompleteLog(LogPath("again.mcap"), 60, 10);
  const std::vector<std::byte> source = ReadBytes(LogPath("again.mcap"));
  fs::create_directories(out_);
  runtime::testing::WriteBytes((out_ / "again.mcap.part").string(),
                               std::vector<std::byte>(source.begin(), source.begin() + 5000));
  StartService();
  ASSERT_EQ(RunDownload(Download("again.mcap"), out_text_, err_text_), 0) << err_text_.str();
  EXPECT_THAT(out_text_.str(), HasSubstr("resuming again.mcap at byte 5000 of"));
  EXPECT_EQ(ReadBytes((out_ / "again.mcap").string()), source);
  service_->Stop();
  EXPECT_EQ(service_->counters().bytes_served, source.size() - 5000);
}

TEST_F(LogDownloadTest, HashMismatchKeepsNothingAndNamesBothHashes) {
  WriteCompleteLog(LogPath("swap.mcap"), 30, 10);
  const std::string listed_sha = CoreutilsSha256(LogPath("swap.mcap"));
  StartService();
  DownloadOptions options = Download("swap.mcap");
  // Between listing and transfer the log is replaced by one of the same size.
  options.hooks.after_listing = [&] {
    std::vector<std::byte> other = ReadBytes(LogPath("swap.mcap"));
    other[other.size() / 2] ^= std::byte{0xFF};
    runtime::testing::WriteBytes(LogPath("swap.tmp"), other);
    fs::rename(LogPath("swap.tmp"), LogPath("swap.mcap"));
  };
  EXPECT_EQ(RunDownload(options, out_text_, err_text_), 1);
  const std::string found_sha = CoreutilsSha256(LogPath("swap.mcap"));
  EXPECT_THAT(err_text_.str(), HasSubstr("SHA-256 mismatch for swap.mcap: expected " + listed_sha +
                                         " (from the listing), found " + found_sha));
  EXPECT_FALSE(fs::exists(out_ / "swap.mcap"));
  EXPECT_FALSE(fs::exists(out_ / "swap.mcap.part"));
}

TEST_F(LogDownloadTest, LogBeingWrittenDownloadsAsListedAndReads) {
  TestLogWriter live(LogPath("live.mcap"));
  live.Write(0, 30);
  live.FlushChunk();
  live.Write(30, 30);
  live.FlushChunk();
  const uint64_t listed = live.bytes_written();
  StartService();
  DownloadOptions options = Download("live.mcap");
  // The log grows after the listing; the download still gets the listed bytes.
  options.hooks.after_listing = [&] {
    live.Write(60, 10);
    live.FlushChunk();
  };
  ASSERT_EQ(RunDownload(options, out_text_, err_text_), 0) << err_text_.str();
  EXPECT_THAT(out_text_.str(), HasSubstr("in-progress log"));
  const std::string saved = (out_ / "live.mcap").string();
  EXPECT_EQ(fs::file_size(saved), listed);
  EXPECT_EQ(ReadBytes(saved), ReadBytes(LogPath("live.mcap"), listed));
  log::McapReader reader = log::McapReader::Open(saved);
  uint64_t messages = 0;
  reader.ForEachMessage([&](const log::MessageView&) {
    ++messages;
    return true;
  });
  EXPECT_EQ(messages, 60U);
  live.Close();
}

TEST_F(LogDownloadTest, GivesUpAfterTheRetriesWithoutProgressAndKeepsThePart) {
  WriteCompleteLog(LogPath("dead.mcap"), 20, 10);
  TransferCutter transfers;
  transfers.CutAlways();
  StartService({.before_send = [&](const std::string&, uint64_t offset) {
    return transfers.BeforeSend(offset);
  }});
  DownloadOptions options = Download("dead.mcap");
  options.retries = 2;
  EXPECT_EQ(RunDownload(options, out_text_, err_text_), 1);
  EXPECT_THAT(err_text_.str(), HasSubstr("giving up after 2 retries without progress"));
  EXPECT_THAT(err_text_.str(), HasSubstr("run the same command to resume"));
  EXPECT_FALSE(fs::exists(out_ / "dead.mcap"));
  EXPECT_TRUE(fs::exists(out_ / "dead.mcap.part"));
  service_->Stop();
  EXPECT_EQ(service_->counters().transfers_started, 3U);
}

TEST_F(LogDownloadTest, BadInputExitsWith2) {
  WriteCompleteLog(LogPath("x.mcap"), 5, 5);
  StartService();
  DownloadOptions traversal = Download("../../etc/passwd");
  EXPECT_EQ(RunDownload(traversal, out_text_, err_text_), 2);
  EXPECT_THAT(err_text_.str(), HasSubstr("log name: expected"));

  DownloadOptions unknown = Download("nope.mcap");
  EXPECT_EQ(RunDownload(unknown, out_text_, err_text_), 2);
  EXPECT_THAT(err_text_.str(), HasSubstr("expected the service to list nope.mcap"));

  DownloadOptions wrong_token = Download("x.mcap");
  wrong_token.access.token = "wrong";
  EXPECT_EQ(RunDownload(wrong_token, out_text_, err_text_), 2);
  EXPECT_THAT(err_text_.str(), HasSubstr("answered 401"));

  DownloadOptions bad_url = Download("x.mcap");
  bad_url.access.url = "https://127.0.0.1:1";
  EXPECT_EQ(RunDownload(bad_url, out_text_, err_text_), 2);
  EXPECT_THAT(err_text_.str(), HasSubstr("expected --url http://HOST:PORT"));

  DownloadOptions no_token = Download("x.mcap");
  no_token.access.token.clear();
  ::unsetenv("ROVER_LOG_TOKEN");
  EXPECT_EQ(RunDownload(no_token, out_text_, err_text_), 2);
  EXPECT_THAT(err_text_.str(), HasSubstr("found none of them"));
  EXPECT_FALSE(fs::exists(out_ / "x.mcap"));
}

TEST_F(LogDownloadTest, ListPrintsATableOrTheRawJson) {
  WriteCompleteLog(LogPath("done.mcap"), 101, 10);
  TestLogWriter live(LogPath("live.mcap"));
  live.Write(0, 10);
  live.FlushChunk();
  StartService();
  const std::string token_file = dir_.File("token").string();
  std::ofstream(token_file) << kToken << "\n";

  ListOptions options{.access = Access("")};
  options.access.token_file = token_file;
  ASSERT_EQ(RunList(options, out_text_, err_text_), 0) << err_text_.str();
  const std::string table = out_text_.str();
  EXPECT_THAT(table, HasSubstr("NAME"));
  EXPECT_THAT(table, HasSubstr("done.mcap"));
  EXPECT_THAT(table, HasSubstr("complete"));
  EXPECT_THAT(table, HasSubstr("in-progress"));
  EXPECT_THAT(table, HasSubstr("1.000 s"));  // 101 messages 10 ms apart
  EXPECT_THAT(table, HasSubstr(CoreutilsSha256(LogPath("done.mcap")).substr(0, 12)));
  EXPECT_THAT(table, HasSubstr("2 logs"));

  std::ostringstream json;
  options.json = true;
  ASSERT_EQ(RunList(options, json, err_text_), 0);
  const auto entries = log::ParseLogListingJson(json.str());
  ASSERT_EQ(entries.size(), 2U);
  EXPECT_EQ(entries[0].sha256, CoreutilsSha256(LogPath("done.mcap")));

  // The token from the environment.
  ::setenv("ROVER_LOG_TOKEN", kToken, 1);
  ListOptions from_env{.access = Access("")};
  std::ostringstream ignored;
  EXPECT_EQ(RunList(from_env, ignored, err_text_), 0);
  ::unsetenv("ROVER_LOG_TOKEN");

  ListOptions wrong{.access = Access("nope")};
  EXPECT_EQ(RunList(wrong, ignored, err_text_), 2);
  EXPECT_THAT(err_text_.str(), HasSubstr("answered 401"));

  const std::string url = Access().url;
  service_->Stop();
  ListOptions unreachable;
  unreachable.access.url = url;
  unreachable.access.token = kToken;
  unreachable.access.connect_timeout_s = 2;
  EXPECT_EQ(RunList(unreachable, ignored, err_text_), 1);
  EXPECT_THAT(err_text_.str(), HasSubstr("cannot get the log listing"));
  live.Close();
}

}  // namespace
}  // namespace rover::host
