#ifndef ROVER_TESTS_CORE_LOG_MCAP_MCAP_TEST_UTIL_H_
#define ROVER_TESTS_CORE_LOG_MCAP_MCAP_TEST_UTIL_H_

// Helpers shared by the MCAP tests: file bytes, and a
// seeded generator of logs whose expected content is known.

#include <cstddef>
#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

#include "core/log/mcap/mcap_reader.h"
#include "core/log/mcap/mcap_writer.h"
#include "tests/support/temp_dir.h"

namespace rover::log::testing {

using TempDir = rover::testing::TempDir;

std::vector<std::byte> ReadFile(const std::string& path);
void WriteFile(const std::string& path, const std::vector<std::byte>& bytes);

/// A message as the test wrote it (owning its data).
struct TestMessage {
  uint16_t channel_id = 0;
  uint32_t sequence = 0;
  uint64_t log_time = 0;
  uint64_t publish_time = 0;
  std::vector<std::byte> data;
  bool operator==(const TestMessage&) const = default;
};
std::ostream& operator<<(std::ostream& os, const TestMessage& m);

TestMessage ToTestMessage(const MessageView& view);

/// What WriteTestLog() wrote.
struct TestLog {
  std::vector<Schema> schemas;
  std::vector<Channel> channels;
  std::vector<TestMessage> messages;  // In write (= file) order.
  std::vector<Metadata> metadata;
};

/// Writes `message_count` messages with seeded random payloads (0..400
/// bytes, some highly compressible) on three channels of two schemas, plus one
/// metadata record, and closes the file. Log times
/// increase by 1..2 ms per message; with `shuffle_times` they also jump back
/// and forth across channels, so file order and log-time order differ.
TestLog WriteTestLog(const std::string& path, const McapWriterOptions& options,
                     size_t message_count, uint32_t seed, bool shuffle_times = false);

/// All messages `reader` delivers, in the requested order.
std::vector<TestMessage> ReadAll(McapReader& reader, const ReadOptions& options = {});

/// Describes damage entries for failure messages.
std::string Describe(const std::vector<Damage>& damage);

}  // namespace rover::log::testing

#endif  // ROVER_TESTS_CORE_LOG_MCAP_MCAP_TEST_UTIL_H_
