#ifndef ROVER_CORE_LOG_MCAP_MCAP_TYPES_H_
#define ROVER_CORE_LOG_MCAP_MCAP_TYPES_H_

// Plain records shared by the MCAP writer and reader (https://mcap.dev/spec).
//
// Times are uint64 nanoseconds as MCAP stores them; the rover writes
// CLOCK_MONOTONIC stamps (rover::Time::nanoseconds()), which are never negative.

#include <cstddef>
#include <cstdint>
#include <map>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace rover::log {

/// Thrown for I/O failures, misuse of the writer, and input that is not an MCAP
/// file at all (bad magic, no complete Header record). Damage inside an MCAP
/// file is never thrown; the reader reports it through `Damage` entries.
class McapError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Chunk compression. Stored in the file as "", "zstd" or "lz4" (LZ4 frame format).
enum class Compression { kNone, kZstd, kLz4 };

/// The MCAP compression string for `compression`: "", "zstd" or "lz4".
std::string_view CompressionName(Compression compression);

/// Header record (op 0x01).
struct Header {
  std::string profile;
  std::string library;
  bool operator==(const Header&) const = default;
};

/// Schema record (op 0x03). Ids are never 0 (0 means "no schema").
struct Schema {
  uint16_t id = 0;
  std::string name;
  std::string encoding;
  std::vector<std::byte> data;
  bool operator==(const Schema&) const = default;
};

/// Channel record (op 0x04). `schema_id` 0 means the channel has no schema.
struct Channel {
  uint16_t id = 0;
  uint16_t schema_id = 0;
  std::string topic;
  std::string message_encoding;
  std::map<std::string, std::string> metadata;
  bool operator==(const Channel&) const = default;
};

/// Statistics record (op 0x0B) of the summary section.
struct Statistics {
  uint64_t message_count = 0;
  uint16_t schema_count = 0;
  uint32_t channel_count = 0;
  uint32_t attachment_count = 0;
  uint32_t metadata_count = 0;
  uint32_t chunk_count = 0;
  uint64_t message_start_time = 0;  ///< Earliest log_time; 0 when there are no messages.
  uint64_t message_end_time = 0;    ///< Latest log_time; 0 when there are no messages.
  std::map<uint16_t, uint64_t> channel_message_counts;
  bool operator==(const Statistics&) const = default;
};

/// Metadata record (op 0x0C): named string key/value pairs.
struct Metadata {
  std::string name;
  std::map<std::string, std::string> metadata;
  bool operator==(const Metadata&) const = default;
};

/// Where an Attachment record (op 0x09) is and what it holds, without its data.
struct AttachmentInfo {
  uint64_t offset = 0;  ///< File offset of the record's opcode byte.
  uint64_t length = 0;  ///< Record length including the 9-byte opcode + length prefix.
  uint64_t log_time = 0;
  uint64_t create_time = 0;
  std::string name;
  std::string media_type;
  uint64_t data_size = 0;
  bool operator==(const AttachmentInfo&) const = default;
};

/// Something unreadable or inconsistent in a file, and where it is.
struct Damage {
  uint64_t offset = 0;  ///< File offset of the damaged record (or of the cut, for truncation).
  std::string what;     ///< What was expected and what was found.
};

}  // namespace rover::log

#endif  // ROVER_CORE_LOG_MCAP_MCAP_TYPES_H_
