#ifndef ROVER_FIRMWARE_RUNTIME_LOG_SERVICE_HTTP_RANGE_H_
#define ROVER_FIRMWARE_RUNTIME_LOG_SERVICE_HTTP_RANGE_H_

// The single byte range of an HTTP Range header (RFC 9110, section 14), as
// the log service answers it.

#include <cstdint>
#include <string_view>

namespace rover::runtime {

struct ByteRangeRequest {
  enum class Kind {
    kWhole,          ///< No usable Range header: send everything with 200.
    kPartial,        ///< Send [offset_bytes, offset_bytes + length_bytes) with 206.
    kUnsatisfiable,  ///< Answer 416 with "Content-Range: bytes */size".
  };
  Kind kind = Kind::kWhole;
  uint64_t offset_bytes = 0;
  uint64_t length_bytes = 0;
};

/// Interprets `header` (the value of Range, empty if absent) for a
/// representation of `size_bytes`. Accepts "bytes=a-b", "bytes=a-" and
/// "bytes=-n" (the last n bytes); an end past the size is clamped. A start at
/// or past the size, a suffix of 0 bytes, or any range of an empty file is
/// unsatisfiable. Headers the service does not honour (other units, several
/// ranges, malformed or reversed ranges) are ignored as RFC 9110 allows,
/// which means the whole representation is sent.
ByteRangeRequest ParseRangeHeader(std::string_view header, uint64_t size_bytes);

}  // namespace rover::runtime

#endif  // ROVER_FIRMWARE_RUNTIME_LOG_SERVICE_HTTP_RANGE_H_
