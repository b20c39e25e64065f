#ifndef ROVER_TESTS_FIRMWARE_RUNTIME_LOG_SERVICE_LOG_TEST_UTIL_H_
#define ROVER_TESTS_FIRMWARE_RUNTIME_LOG_SERVICE_LOG_TEST_UTIL_H_

// Shared by the log service tests: MCAP logs with known contents, an
// independent SHA-256 (coreutils sha256sum), and raw HTTP over a socket.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/log/mcap/mcap_writer.h"
#include "firmware/runtime/log_service/log_service_options.h"

namespace rover::runtime::testing {

inline constexpr char kToken[] = "s3cret-token_for.tests";
inline constexpr uint64_t kFirstTimeNs = 1'000'000'000;
inline constexpr uint64_t kPeriodNs = 10'000'000;

/// The log time of message `index`.
inline uint64_t MessageTimeNs(int index) {
  return kFirstTimeNs + static_cast<uint64_t>(index) * kPeriodNs;
}

/// An uncompressed MCAP writer with one schemaless channel; messages carry
/// `payload_bytes` of deterministic noise. Chunks close only on FlushChunk().
class TestLogWriter {
 public:
  explicit TestLogWriter(const std::string& path, size_t payload_bytes = 2000);
  /// Writes messages [first, first + count) (times MessageTimeNs(i)).
  void Write(int first, int count);
  /// Closes the open chunk: its bytes reach the file in one write.
  void FlushChunk() { writer_.FlushChunk(); }
  /// Bytes written to the file so far.
  uint64_t bytes_written() const { return writer_.stats().bytes_written; }
  void Close() { writer_.Close(); }

 private:
  log::McapWriter writer_;
  uint16_t channel_ = 0;
  size_t payload_bytes_;
};

/// A complete log of `messages` messages, `per_chunk` per chunk.
void WriteCompleteLog(const std::string& path, int messages, int per_chunk,
                      size_t payload_bytes = 2000);

/// The file's bytes (the first `length` only, if given).
std::vector<std::byte> ReadBytes(const std::string& path,
                                 std::optional<uint64_t> length = std::nullopt);
std::string ReadText(const std::string& path);
void WriteBytes(const std::string& path, const std::vector<std::byte>& bytes);

/// SHA-256 from coreutils `sha256sum` (of the first `length` bytes, if given),
/// independent of the code under test.
std::string CoreutilsSha256(const std::string& path, std::optional<uint64_t> length = std::nullopt);

/// Options for a service on 127.0.0.1, any port, no bandwidth limit.
LogServiceOptions TestOptions(const std::string& folder);

struct RawResponse {
  int status = 0;
  std::string head;  ///< Status line and headers.
  std::string body;
  /// The value of header `name` (case-insensitive), or empty.
  std::string Header(const std::string& name) const;
};

/// Sends `request` verbatim to 127.0.0.1:`port` and reads until the server
/// closes (send "Connection: close"). Fails the test on socket errors.
RawResponse RawHttp(int port, const std::string& request);

/// "<method> <target> HTTP/1.1" with Host, "Authorization: <authorization>"
/// (the test token by default; none if empty), `extra_headers` (each line
/// ending in "\r\n") and Connection: close.
RawResponse RawGet(int port, const std::string& target,
                   std::optional<std::string> authorization = std::nullopt,
                   const std::string& method = "GET", const std::string& extra_headers = "");

}  // namespace rover::runtime::testing

#endif  // ROVER_TESTS_FIRMWARE_RUNTIME_LOG_SERVICE_LOG_TEST_UTIL_H_
