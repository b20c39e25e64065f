// The board's HTTP log service on a real socket (127.0.0.1, port 0): listing,
// downloads with ranges, tokens, read-only methods, name validation and
// symlinks, logs still being written, the transfer limit, pacing, options.

#include "firmware/runtime/log_service/log_service.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <httplib.h>
#include <sys/resource.h>
#include <unistd.h>

#include <chrono>
#include <condition_variable>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <set>
#include <thread>

#include "core/log/archive/log_listing.h"
#include "core/log/mcap/mcap_reader.h"
#include "firmware/runtime/log_service/http_range.h"
#include "firmware/runtime/log_service/rate_limiter.h"
#include "tests/firmware/runtime/log_service/log_test_util.h"
#include "tests/support/temp_dir.h"

namespace rover::runtime {
namespace {

namespace fs = std::filesystem;
using testing::CoreutilsSha256;
using ::testing::HasSubstr;
using testing::kToken;
using testing::MessageTimeNs;
using testing::RawGet;
using testing::ReadBytes;
using testing::ReadText;
using testing::TestLogWriter;
using testing::TestOptions;
using testing::WriteCompleteLog;

std::string AsString(const std::vector<std::byte>& bytes) {
  return {reinterpret_cast<const char*>(bytes.data()), bytes.size()};
}

class LogServiceTest : public ::testing::Test {
 protected:
  void SetUp() override { fs::create_directories(folder_); }

  void StartService(LogServiceHooks hooks = {}) {
    service_ = std::make_unique<LogService>(options_, std::move(hooks));
    service_->Start();
    ASSERT_GT(service_->port(), 0);
  }

  httplib::Client Client(const std::string& token = kToken) const {
    httplib::Client client("127.0.0.1", service_->port());
    client.set_read_timeout(30, 0);
    if (!token.empty()) client.set_bearer_token_auth(token);
    return client;
  }

  std::vector<log::LogListingEntry> List() {
    auto client = Client();
    auto result = client.Get("/logs");
    EXPECT_TRUE(result) << httplib::to_string(result.error());
    if (!result) return {};
    EXPECT_EQ(result->status, 200) << result->body;
    EXPECT_EQ(result->get_header_value("Content-Type"), "application/json");
    return log::ParseLogListingJson(result->body);
  }

  std::string LogPath(const std::string& name) const { return (folder_ / name).string(); }

  rover::testing::TempDir dir_{"log_service"};
  fs::path folder_ = dir_.path() / "logs";
  LogServiceOptions options_ = TestOptions(folder_.string());
  std::unique_ptr<LogService> service_;
};

TEST_F(LogServiceTest, ListsLogsWithSizeTimeRangeAndIndependentlyCheckedSha256) {
  WriteCompleteLog(LogPath("b_flight.mcap"), 60, 9);
  WriteCompleteLog(LogPath("a_flight.mcap"), 5, 5, 100);
  // Not listed: other names, hidden files, folders.
  std::ofstream(LogPath("notes.txt")) << "x";
  std::ofstream(LogPath(".hidden.mcap")) << "x";
  fs::create_directory(folder_ / "dir.mcap");
  StartService();

  const auto listing = List();
  ASSERT_EQ(listing.size(), 2U);
  EXPECT_EQ(listing[0].name, "a_flight.mcap");
  EXPECT_EQ(listing[1].name, "b_flight.mcap");
  const log::LogListingEntry& b = listing[1];
  EXPECT_EQ(b.size_bytes, fs::file_size(LogPath("b_flight.mcap")));
  EXPECT_EQ(b.sha256, CoreutilsSha256(LogPath("b_flight.mcap")));
  EXPECT_EQ(b.start_time_ns, MessageTimeNs(0));
  EXPECT_EQ(b.end_time_ns, MessageTimeNs(59));
  EXPECT_TRUE(b.complete);
  EXPECT_EQ(listing[0].sha256, CoreutilsSha256(LogPath("a_flight.mcap")));
  EXPECT_EQ(listing[0].end_time_ns, MessageTimeNs(4));

  // The raw JSON carries exactly the documented fields.
  auto client = Client();
  const auto raw = client.Get("/logs");
  ASSERT_TRUE(raw);
  for (const char* key : {"\"name\"", "\"size_bytes\"", "\"start_time_ns\"", "\"end_time_ns\"",
                          "\"sha256\"", "\"complete\""}) {
    EXPECT_THAT(raw->body, HasSubstr(key));
  }
  EXPECT_EQ(service_->counters().listings, 2U);
}

TEST_F(LogServiceTest, ServesWholeLogsAndByteRanges) {
  const std::string path = LogPath("r.mcap");
  WriteCompleteLog(path, 30, 10);
  const std::string file = AsString(ReadBytes(path));
  const auto size = file.size();
  StartService();
  auto client = Client();

  auto whole = client.Get("/logs/r.mcap");
  ASSERT_TRUE(whole);
  EXPECT_EQ(whole->status, 200);
  EXPECT_EQ(whole->body, file);
  EXPECT_EQ(whole->get_header_value("Accept-Ranges"), "bytes");
  EXPECT_EQ(whole->get_header_value("ETag"), "\"" + CoreutilsSha256(path) + "\"");
  EXPECT_EQ(whole->get_header_value("Content-Length"), std::to_string(size));

  const auto range = [&](const std::string& spec) {
    auto result = client.Get("/logs/r.mcap", {{"Range", spec}});
    EXPECT_TRUE(result) << spec;
    return result;
  };
  auto middle = range("bytes=10-99");
  EXPECT_EQ(middle->status, 206);
  EXPECT_EQ(middle->get_header_value("Content-Range"), "bytes 10-99/" + std::to_string(size));
  EXPECT_EQ(middle->body, file.substr(10, 90));

  auto open_end = range("bytes=" + std::to_string(size - 5) + "-");
  EXPECT_EQ(open_end->status, 206);
  EXPECT_EQ(open_end->body, file.substr(size - 5));

  auto suffix = range("bytes=-16");
  EXPECT_EQ(suffix->status, 206);
  EXPECT_EQ(suffix->body, file.substr(size - 16));

  auto clamped = range("bytes=100-99999999");
  EXPECT_EQ(clamped->status, 206);
  EXPECT_EQ(clamped->get_header_value("Content-Range"),
            "bytes 100-" + std::to_string(size - 1) + "/" + std::to_string(size));
  EXPECT_EQ(clamped->body, file.substr(100));

  auto beyond = range("bytes=" + std::to_string(size) + "-");
  EXPECT_EQ(beyond->status, 416);
  EXPECT_EQ(beyond->get_header_value("Content-Range"), "bytes */" + std::to_string(size));
  EXPECT_THAT(beyond->body, HasSubstr("expected a range starting below the"));

  auto head = client.Head("/logs/r.mcap");
  ASSERT_TRUE(head);
  EXPECT_EQ(head->status, 200);
  EXPECT_EQ(head->get_header_value("Content-Length"), std::to_string(size));
  EXPECT_TRUE(head->body.empty());

  // A client that has its last byte may be faster than the server's
  // bookkeeping; Stop() joins the workers, so the counters are final.
  service_->Stop();
  const LogServiceCounters c = service_->counters();
  EXPECT_EQ(c.transfers_completed, 5U);
  EXPECT_EQ(c.partial_responses, 4U);
  EXPECT_EQ(c.refused_range, 1U);
  EXPECT_EQ(c.bytes_served, size + 90 + 5 + 16 + (size - 100));
  EXPECT_EQ(c.active_transfers, 0U);
}

TEST_F(LogServiceTest, MissingOrWrongTokenIsRefusedWith401) {
  WriteCompleteLog(LogPath("t.mcap"), 3, 3);
  StartService();
  for (const std::string& auth :
       {std::string(""), std::string("Bearer wrong"), std::string("Bearer ") + kToken + "x",
        std::string("Basic ") + kToken, std::string("Bearer")}) {
    for (const char* target : {"/logs", "/logs/t.mcap", "/nowhere"}) {
      const auto response = RawGet(service_->port(), target, auth);
      EXPECT_EQ(response.status, 401) << auth << " " << target;
      EXPECT_EQ(response.Header("WWW-Authenticate"), "Bearer realm=\"rover-logs\"");
      EXPECT_THAT(response.body, HasSubstr("expected \"Authorization: Bearer <token>\""));
      EXPECT_THAT(response.body, ::testing::Not(HasSubstr("MCAP")));
    }
  }
  EXPECT_THAT(RawGet(service_->port(), "/logs", "").body, HasSubstr("found no Authorization"));
  EXPECT_THAT(RawGet(service_->port(), "/logs", "Bearer nope").body,
              HasSubstr("found a token that does not match"));
  // The scheme is case-insensitive; the token is not.
  EXPECT_EQ(RawGet(service_->port(), "/logs", std::string("bearer ") + kToken).status, 200);
  EXPECT_EQ(RawGet(service_->port(), "/logs", "Bearer S3CRET-TOKEN_FOR.TESTS").status, 401);
  // Requests cpp-httplib answers before routing (a malformed Range) are
  // authenticated too.
  const auto bad_range =
      RawGet(service_->port(), "/logs/t.mcap", "", "GET", "Range: bytes=abc\r\n");
  EXPECT_EQ(bad_range.status, 401);
  EXPECT_TRUE(bad_range.body.find("MCAP") == std::string::npos);
  const auto bad_range_ok =
      RawGet(service_->port(), "/logs/t.mcap", std::nullopt, "GET", "Range: bytes=abc\r\n");
  EXPECT_EQ(bad_range_ok.status, 416);
  EXPECT_THAT(bad_range_ok.body, HasSubstr("expected a Range header of the form bytes=a-b"));
  EXPECT_EQ(service_->counters().refused_unauthorized, 19U);
  EXPECT_EQ(service_->counters().bytes_served, 0U);
}

TEST_F(LogServiceTest, IsReadOnlyAnyMethodButGetAndHeadIs405) {
  WriteCompleteLog(LogPath("m.mcap"), 3, 3);
  StartService();
  for (const std::string method : {"POST", "PUT", "DELETE", "PATCH", "OPTIONS"}) {
    const auto response = RawGet(service_->port(), "/logs/m.mcap", std::nullopt, method);
    EXPECT_EQ(response.status, 405) << method;
    EXPECT_EQ(response.Header("Allow"), "GET, HEAD");
    EXPECT_THAT(response.body, HasSubstr("expected GET or HEAD, found " + method));
  }
  auto client = Client();
  auto post = client.Post("/logs/m.mcap", "overwrite", "application/octet-stream");
  ASSERT_TRUE(post);
  EXPECT_EQ(post->status, 405);
  // Authentication comes first: without the token a POST is 401.
  EXPECT_EQ(RawGet(service_->port(), "/logs", "", "POST").status, 401);
  EXPECT_EQ(service_->counters().refused_method, 6U);
  EXPECT_EQ(ReadBytes(LogPath("m.mcap")).size(), fs::file_size(LogPath("m.mcap")));
}

TEST_F(LogServiceTest, TraversalAndOddNamesAreRefusedBeforeTouchingTheFileSystem) {
  WriteCompleteLog(LogPath("ok.mcap"), 3, 3);
  StartService();
  for (const std::string target :
       {"/logs/../../etc/passwd", "/logs/..%2F..%2Fetc%2Fpasswd", "/logs/%2e%2e%2fetc%2fpasswd",
        "/logs/%2E%2E/%2E%2E/etc/passwd", "/logs//etc/passwd", "/logs/%2Fetc%2Fpasswd.mcap",
        "/logs/ok.mcap%00.txt", "/logs/a%00b.mcap", "/logs/.hidden.mcap", "/logs/ok.mcap/",
        "/logs/..", "/logs/%252e%252e%252fx.mcap", "/logs/x%20y.mcap"}) {
    const auto response = RawGet(service_->port(), target);
    EXPECT_EQ(response.status, 400) << target;
    EXPECT_THAT(response.body, HasSubstr("expected")) << target;
    EXPECT_THAT(response.body, ::testing::Not(HasSubstr("root:"))) << target;
  }
  EXPECT_EQ(RawGet(service_->port(), "/etc/passwd").status, 404);
  EXPECT_EQ(RawGet(service_->port(), "/../etc/passwd").status, 404);
  EXPECT_EQ(RawGet(service_->port(), "/logs/missing.mcap").status, 404);
  EXPECT_EQ(RawGet(service_->port(), "/logs/ok.mcap").status, 200);
  EXPECT_EQ(service_->counters().refused_bad_name, 13U);
}

TEST_F(LogServiceTest, SymlinksOutOfTheFolderAreRefusedWith403AndNotListed) {
  WriteCompleteLog(LogPath("real.mcap"), 3, 3);
  const fs::path outside = dir_.path() / "outside";
  fs::create_directories(outside);
  WriteCompleteLog((outside / "secret.mcap").string(), 3, 3);
  fs::create_symlink(outside / "secret.mcap", folder_ / "escape.mcap");
  fs::create_symlink("../outside/secret.mcap", folder_ / "relative_escape.mcap");
  fs::create_symlink("/etc/passwd", folder_ / "passwd.mcap");
  fs::create_symlink(folder_ / "real.mcap", folder_ / "alias.mcap");  // stays inside: fine
  fs::create_symlink(folder_ / "gone.mcap", folder_ / "dangling.mcap");
  StartService();

  for (const std::string name : {"escape.mcap", "relative_escape.mcap", "passwd.mcap"}) {
    const auto response = RawGet(service_->port(), "/logs/" + name);
    EXPECT_EQ(response.status, 403) << name;
    EXPECT_THAT(response.body, HasSubstr("symbolic link that leads outside the log folder"));
    EXPECT_THAT(response.body, ::testing::Not(HasSubstr("outside/secret")));
  }
  EXPECT_EQ(RawGet(service_->port(), "/logs/dangling.mcap").status, 404);
  const auto alias = RawGet(service_->port(), "/logs/alias.mcap");
  EXPECT_EQ(alias.status, 200);
  EXPECT_EQ(alias.body, AsString(ReadBytes(LogPath("real.mcap"))));

  std::set<std::string> names;
  for (const auto& entry : List()) names.insert(entry.name);
  EXPECT_EQ(names, (std::set<std::string>{"alias.mcap", "real.mcap"}));
  EXPECT_EQ(service_->counters().refused_outside_folder, 3U);
}

TEST_F(LogServiceTest, LogBeingWrittenIsServedUpToItsLastCompleteChunk) {
  // A live writer, never closed during the checks: two chunks on disk, more
  // messages buffered in its open chunk.
  const std::string live_path = LogPath("live.mcap");
  TestLogWriter live(live_path);
  live.Write(0, 20);
  live.FlushChunk();
  live.Write(20, 20);
  live.FlushChunk();
  const uint64_t two_chunks = live.bytes_written();
  live.Write(40, 5);
  // A copy cut in the middle of its third chunk, as a power cut or a write
  // in progress would leave it.
  live.FlushChunk();
  const uint64_t three_chunks = live.bytes_written();
  const std::vector<std::byte> torn =
      ReadBytes(live_path, two_chunks + (three_chunks - two_chunks) / 2);
  testing::WriteBytes(LogPath("torn.mcap"), torn);
  StartService();

  auto listing = List();
  ASSERT_EQ(listing.size(), 2U);
  const log::LogListingEntry& live_entry = listing[0];
  const log::LogListingEntry& torn_entry = listing[1];
  EXPECT_EQ(torn_entry.name, "torn.mcap");
  EXPECT_FALSE(torn_entry.complete);
  EXPECT_EQ(torn_entry.size_bytes, two_chunks);
  EXPECT_EQ(torn_entry.sha256, CoreutilsSha256(LogPath("torn.mcap"), two_chunks));
  EXPECT_EQ(torn_entry.start_time_ns, MessageTimeNs(0));
  EXPECT_EQ(torn_entry.end_time_ns, MessageTimeNs(39));
  EXPECT_FALSE(live_entry.complete);
  EXPECT_EQ(live_entry.size_bytes, three_chunks);
  EXPECT_EQ(live_entry.end_time_ns, MessageTimeNs(44));

  // The download is exactly the servable prefix, and the project's reader
  // reads every message of the two complete chunks from it.
  auto client = Client();
  auto served = client.Get("/logs/torn.mcap");
  ASSERT_TRUE(served);
  EXPECT_EQ(served->status, 200);
  EXPECT_EQ(served->get_header_value("X-Rover-Log-Complete"), "false");
  ASSERT_EQ(served->body.size(), two_chunks);
  EXPECT_EQ(served->body, AsString(torn).substr(0, two_chunks));
  const auto bytes = std::as_bytes(std::span(served->body.data(), served->body.size()));
  log::McapReader reader = log::McapReader::Open(bytes);
  EXPECT_TRUE(reader.truncated());
  uint64_t messages = 0;
  uint64_t last_time = 0;
  reader.ForEachMessage([&](const log::MessageView& m) {
    ++messages;
    last_time = m.log_time;
    return true;
  });
  EXPECT_EQ(messages, 40U);
  EXPECT_EQ(last_time, MessageTimeNs(39));
  ASSERT_EQ(reader.damage().size(), 1U);
  EXPECT_THAT(reader.damage()[0].what, HasSubstr("truncated"));

  // The live log grows; the listing follows chunk by chunk (hashing only the
  // new bytes) and a Range request for the old listed size still gets
  // exactly those bytes.
  live.Write(45, 30);
  live.FlushChunk();
  listing = List();
  EXPECT_EQ(listing[0].size_bytes, live.bytes_written());
  EXPECT_EQ(listing[0].sha256, CoreutilsSha256(live_path, live.bytes_written()));
  EXPECT_EQ(listing[0].end_time_ns, MessageTimeNs(74));
  auto old_prefix =
      client.Get("/logs/live.mcap", {{"Range", "bytes=0-" + std::to_string(three_chunks - 1)}});
  ASSERT_TRUE(old_prefix);
  EXPECT_EQ(old_prefix->status, 206);
  EXPECT_EQ(old_prefix->body, AsString(ReadBytes(live_path, three_chunks)));

  live.Close();
  listing = List();
  EXPECT_TRUE(listing[0].complete);
  EXPECT_EQ(listing[0].size_bytes, fs::file_size(live_path));
  EXPECT_EQ(listing[0].sha256, CoreutilsSha256(live_path));
}

// Holds transfers before their first chunk until released.
class TransferGate {
 public:
  bool BeforeSend(uint64_t offset) {
    if (offset != 0) return true;
    std::unique_lock lock(mutex_);
    ++held_;
    changed_.notify_all();
    changed_.wait(lock, [&] { return released_; });
    return true;
  }
  void WaitUntilHeld(int n) {
    std::unique_lock lock(mutex_);
    changed_.wait(lock, [&] { return held_ >= n; });
  }
  void Release() {
    std::lock_guard lock(mutex_);
    released_ = true;
    changed_.notify_all();
  }

 private:
  std::mutex mutex_;
  std::condition_variable changed_;
  int held_ = 0;
  bool released_ = false;
};

TEST_F(LogServiceTest, MoreThanMaxConcurrentTransfersGet503WithRetryAfter) {
  WriteCompleteLog(LogPath("big.mcap"), 40, 10);
  const std::string file = AsString(ReadBytes(LogPath("big.mcap")));
  options_.max_concurrent_transfers = 2;
  options_.retry_after_s = 7;
  TransferGate gate;
  StartService({.before_send = [&](const std::string&, uint64_t offset) {
    return gate.BeforeSend(offset);
  }});

  // Raw requests read until the server closes the connection, which it does
  // only after the transfer released its slot: the checks below need no wait.
  std::vector<std::string> bodies(2);
  std::vector<std::thread> downloads;
  for (int i = 0; i < 2; ++i) {
    downloads.emplace_back([&, i] {
      const auto response = RawGet(service_->port(), "/logs/big.mcap");
      if (response.status == 200) bodies[static_cast<size_t>(i)] = response.body;
    });
  }
  gate.WaitUntilHeld(2);
  EXPECT_EQ(service_->counters().active_transfers, 2U);

  const auto busy = RawGet(service_->port(), "/logs/big.mcap");
  EXPECT_EQ(busy.status, 503);
  EXPECT_EQ(busy.Header("Retry-After"), "7");
  EXPECT_THAT(busy.body, HasSubstr("expected a free transfer slot, found all 2 busy"));
  // Listings, HEAD and refusals are still answered while every slot is busy.
  EXPECT_EQ(RawGet(service_->port(), "/logs").status, 200);
  EXPECT_EQ(RawGet(service_->port(), "/logs/big.mcap", std::nullopt, "HEAD").status, 200);
  EXPECT_EQ(RawGet(service_->port(), "/logs", "Bearer x").status, 401);

  gate.Release();
  for (auto& t : downloads) t.join();
  EXPECT_EQ(bodies[0], file);
  EXPECT_EQ(bodies[1], file);
  const LogServiceCounters c = service_->counters();
  EXPECT_EQ(c.refused_busy, 1U);
  EXPECT_EQ(c.transfers_completed, 2U);
  EXPECT_EQ(c.active_transfers, 0U);
  // A slot is free again.
  EXPECT_EQ(RawGet(service_->port(), "/logs/big.mcap").status, 200);
}

TEST_F(LogServiceTest, CutTransferFreesItsSlotAndIsCountedAsAborted) {
  WriteCompleteLog(LogPath("cut.mcap"), 40, 10);
  options_.max_concurrent_transfers = 1;
  StartService({.before_send = [](const std::string&, uint64_t offset) { return offset == 0; }});
  auto client = Client();
  auto result = client.Get("/logs/cut.mcap");
  EXPECT_FALSE(result && result->body.size() == fs::file_size(LogPath("cut.mcap")));
  // The aborted transfer is counted when its response is gone; the next
  // request then finds the slot free (same cut again: still no 503).
  auto again = client.Get("/logs/cut.mcap");
  EXPECT_FALSE(again && again->status == 503);
  const LogServiceCounters c = service_->counters();
  EXPECT_EQ(c.transfers_started, 2U);
  EXPECT_EQ(c.refused_busy, 0U);
  EXPECT_EQ(c.bytes_served, 2U * 64 * 1024);
}

TEST_F(LogServiceTest, BandwidthLimitPacesTransfers) {
  WriteCompleteLog(LogPath("paced.mcap"), 50, 10);  // ~100 KiB
  const uint64_t size = fs::file_size(LogPath("paced.mcap"));
  options_.bandwidth_limit_bytes_per_s = 400'000;  // 20 KB chunks, 50 ms apart
  StartService();
  auto client = Client();
  const auto start = std::chrono::steady_clock::now();
  auto result = client.Get("/logs/paced.mcap");
  const double elapsed_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_TRUE(result);
  EXPECT_EQ(result->body.size(), size);
  // A lower bound only: the first chunk goes at once, each further one waits
  // its share of the rate.
  const double chunks = std::ceil(static_cast<double>(size) / 20'000.0);
  EXPECT_GE(elapsed_s, (chunks - 1) * 0.05 * 0.95);
}

TEST_F(LogServiceTest, ServiceThreadsRunAtTheConfiguredNiceValue) {
  WriteCompleteLog(LogPath("n.mcap"), 3, 3);
  options_.nice = 7;
  options_.io_class = IoPriorityClass::kBestEffort;
  options_.io_level = 6;
  std::atomic<int> seen_nice{100};
  StartService({.before_send = [&](const std::string&, uint64_t) {
    errno = 0;
    seen_nice = ::getpriority(PRIO_PROCESS, static_cast<id_t>(::gettid()));
    return true;
  }});
  EXPECT_EQ(RawGet(service_->port(), "/logs/n.mcap").status, 200);
  if (service_->priority_warning().empty()) {
    EXPECT_EQ(seen_nice.load(), 7);
  } else {
    // Not fatal: said once, service still serving.
    EXPECT_THAT(service_->priority_warning(), HasSubstr("failed"));
  }
  // The caller's own thread is untouched.
  EXPECT_NE(::getpriority(PRIO_PROCESS, static_cast<id_t>(::gettid())), 7);
}

TEST_F(LogServiceTest, StartReportsBadSetUpAndStopIsIdempotent) {
  options_.log_folder = (dir_.path() / "missing").string();
  LogService missing_folder(options_);
  EXPECT_THAT([&] { missing_folder.Start(); }, ::testing::ThrowsMessage<std::runtime_error>(
                                                   HasSubstr("to be an existing directory")));

  options_ = TestOptions(folder_.string());
  options_.token = "";
  options_.token_file = (dir_.path() / "token").string();
  std::ofstream(options_.token_file) << "  file-token\n";
  StartService();
  EXPECT_EQ(RawGet(service_->port(), "/logs", "Bearer file-token").status, 200);
  const int port = service_->port();

  LogServiceOptions same_port = options_;
  same_port.port = port;
  LogService second(same_port);
  EXPECT_THAT([&] { second.Start(); },
              ::testing::ThrowsMessage<std::runtime_error>(HasSubstr("cannot listen on")));

  service_->Stop();
  service_->Stop();
  EXPECT_FALSE(service_->running());
  EXPECT_EQ(service_->port(), 0);
  service_->Start();  // again, on a new port
  EXPECT_EQ(RawGet(service_->port(), "/logs", "Bearer file-token").status, 200);
}

// --- options --------------------------------------------------------------------

TEST(LogServiceOptionsTest, LoadsEveryKeyAndRejectsBadValues) {
  const ConfigNode root = ConfigNode::LoadString(R"(
log_service:
  bind_address: 0.0.0.0
  port: 8086
  log_folder: /var/lib/rover/logs
  token_file: /etc/rover/log_service.token
  max_concurrent_transfers: 3
  bandwidth_limit_bytes_per_s: 1000000
  nice: 15
  io_class: best_effort
  io_level: 4
  retry_after_s: 9
  read_timeout_s: 20
  write_timeout_s: 30
)",
                                                 "board.yaml");
  const LogServiceOptions o = LogServiceOptions::Load(root.Child("log_service"));
  root.CheckNoUnknownKeysRecursive();
  EXPECT_EQ(o.bind_address, "0.0.0.0");
  EXPECT_EQ(o.port, 8086);
  EXPECT_EQ(o.token_file, "/etc/rover/log_service.token");
  EXPECT_EQ(o.max_concurrent_transfers, 3);
  EXPECT_EQ(o.bandwidth_limit_bytes_per_s, 1'000'000U);
  EXPECT_EQ(o.nice, 15);
  EXPECT_EQ(o.io_class, IoPriorityClass::kBestEffort);
  EXPECT_EQ(o.io_level, 4);
  EXPECT_EQ(o.retry_after_s, 9);

  const auto load_error = [](const std::string& yaml) {
    try {
      LogServiceOptions::Load(ConfigNode::LoadString(yaml, "board.yaml"));
    } catch (const ConfigError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_THAT(load_error("log_folder: /l\ntoken: t\nio_class: realtime\n"), HasSubstr("io_class"));
  EXPECT_THAT(load_error("log_folder: /l\ntoken: t\nport: 70000\n"),
              ::testing::AllOf(HasSubstr("[0, 65535]"), HasSubstr("found 70000")));
  EXPECT_THAT(load_error("log_folder: /l\n"),
              HasSubstr("expected exactly one of token and token_file, found neither"));
  EXPECT_THAT(load_error("log_folder: /l\ntoken: a\ntoken_file: b\n"), HasSubstr("found both"));
  EXPECT_THAT(load_error("token: t\n"), HasSubstr("log_folder"));

  LogServiceOptions bad;
  bad.log_folder = "/l";
  bad.token = "t";
  bad.max_concurrent_transfers = 0;
  EXPECT_THAT([&] { bad.Validate(); }, ::testing::ThrowsMessage<std::invalid_argument>(HasSubstr(
                                           "max_concurrent_transfers: expected 1..64, found 0")));
}

TEST(LogServiceOptionsTest, TokenFileIsTrimmedAndMustHoldAToken) {
  rover::testing::TempDir dir("token");
  LogServiceOptions o;
  o.log_folder = "/l";
  o.token_file = dir.File("token").string();
  std::ofstream(o.token_file) << "\n  abc-123 \n";
  EXPECT_EQ(o.LoadToken(), "abc-123");
  std::ofstream(o.token_file) << " \n";
  EXPECT_THAT([&] { o.LoadToken(); },
              ::testing::ThrowsMessage<std::runtime_error>(HasSubstr("found none")));
  std::ofstream(o.token_file) << "two words";
  EXPECT_THAT([&] { o.LoadToken(); },
              ::testing::ThrowsMessage<std::runtime_error>(HasSubstr("found byte 32")));
  o.token_file = dir.File("missing").string();
  EXPECT_THAT([&] { o.LoadToken(); }, ::testing::ThrowsMessage<std::runtime_error>(
                                          HasSubstr("cannot read the token file")));
}

// --- ranges and pacing ------------------------------------------------------------

TEST(HttpRangeTest, InterpretsSingleByteRanges) {
  using Kind = ByteRangeRequest::Kind;
  const auto check = [](std::string_view header, uint64_t size, Kind kind, uint64_t offset,
                        uint64_t length) {
    const ByteRangeRequest r = ParseRangeHeader(header, size);
    EXPECT_EQ(r.kind, kind) << header;
    if (kind == Kind::kPartial) {
      EXPECT_EQ(r.offset_bytes, offset) << header;
      EXPECT_EQ(r.length_bytes, length) << header;
    }
  };
  check("", 100, Kind::kWhole, 0, 0);
  check("bytes=0-99", 100, Kind::kPartial, 0, 100);
  check("bytes=10-19", 100, Kind::kPartial, 10, 10);
  check("Bytes = 10 - 19", 100, Kind::kWhole, 0, 0);  // "Bytes =" is not the unit syntax
  check("BYTES=10-", 100, Kind::kPartial, 10, 90);
  check("bytes=90-500", 100, Kind::kPartial, 90, 10);
  check("bytes=-30", 100, Kind::kPartial, 70, 30);
  check("bytes=-300", 100, Kind::kPartial, 0, 100);
  check("bytes=100-", 100, Kind::kUnsatisfiable, 0, 0);
  check("bytes=-0", 100, Kind::kUnsatisfiable, 0, 0);
  check("bytes=0-", 0, Kind::kUnsatisfiable, 0, 0);
  check("bytes=20-10", 100, Kind::kWhole, 0, 0);
  check("bytes=0-1,5-6", 100, Kind::kWhole, 0, 0);
  check("items=0-1", 100, Kind::kWhole, 0, 0);
  check("bytes=x-1", 100, Kind::kWhole, 0, 0);
  check("bytes=99999999999999999999999-", 100, Kind::kWhole, 0, 0);
}

TEST(RateLimiterTest, GrantsAtMostTheRateAndCancelWakesWaiters) {
  RateLimiter limiter(1'000'000);
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < 10; ++i) ASSERT_TRUE(limiter.Acquire(50'000));
  const double elapsed_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_GE(elapsed_s, 0.45 * 0.95);  // nine waits of 50 ms; lower bound only

  RateLimiter slow(1);
  EXPECT_TRUE(slow.Acquire(1'000'000'000));                    // the first grant is immediate...
  std::thread waiter([&] { EXPECT_FALSE(slow.Acquire(1)); });  // ...the next waits ~30 years
  slow.Cancel();
  waiter.join();
  EXPECT_FALSE(slow.Acquire(1));
  EXPECT_TRUE(RateLimiter(0).Acquire(uint64_t{1} << 40));
}

}  // namespace
}  // namespace rover::runtime
