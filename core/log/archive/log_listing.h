#ifndef ROVER_CORE_LOG_ARCHIVE_LOG_LISTING_H_
#define ROVER_CORE_LOG_ARCHIVE_LOG_LISTING_H_

// The log listing of the board's log service (GET /logs), as written by the
// service and read by `rover-log list` / `rover-log download`:
//
//   [{"name": "flight_0001.mcap", "size_bytes": 1048576,
//     "start_time_ns": 1000000000, "end_time_ns": 61000000000,
//     "sha256": "9f86d081...", "complete": true}, ...]
//
// size_bytes and sha256 describe the servable bytes: the whole file for a
// complete log, the prefix up to the last complete record for a log still
// being written. The times are log times (CLOCK_MONOTONIC ns, not wall clock)
// of the first and last message in those bytes, null when there is none.

#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace rover::log {

/// One log of the listing.
struct LogListingEntry {
  std::string name;                       ///< Plain file name (IsValidLogName()).
  uint64_t size_bytes = 0;                ///< Servable bytes.
  std::optional<uint64_t> start_time_ns;  ///< Earliest message log time, if any.
  std::optional<uint64_t> end_time_ns;    ///< Latest message log time, if any.
  std::string sha256;     ///< SHA-256 of the servable bytes, 64 lowercase hex characters.
  bool complete = false;  ///< The file ends with a valid summary and footer.
  bool operator==(const LogListingEntry&) const = default;
};

/// A listing that is not valid JSON of the shape above. what() says what was
/// expected, what was found and at which byte offset.
class LogListingError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The JSON array for `entries`, one object per line.
std::string LogListingToJson(const std::vector<LogListingEntry>& entries);

/// Parses a listing. Unknown keys are skipped (any JSON value, nested at most
/// 32 deep); name, size_bytes, sha256 and complete are required, the times may
/// be null or absent. Names must pass IsValidLogName() and sha256 must be 64
/// lowercase hex characters. Throws LogListingError otherwise.
std::vector<LogListingEntry> ParseLogListingJson(std::string_view json);

}  // namespace rover::log

#endif  // ROVER_CORE_LOG_ARCHIVE_LOG_LISTING_H_
