#ifndef ROVER_CORE_LOG_ARCHIVE_MCAP_SERVABLE_H_
#define ROVER_CORE_LOG_ARCHIVE_MCAP_SERVABLE_H_

// How much of an MCAP flight log can be handed out, and what it holds.
//
// A complete log (valid summary, Footer and closing magic) is servable as a
// whole. A log still being written is servable up to the end of its last
// complete record: McapWriter writes each chunk and its message indexes with
// one write(2), and a record whose length prefix points past the end of the
// file is a write in progress (or a cut). A reader of the servable prefix
// therefore never meets a torn record; it sees a truncated log, which
// McapReader reads up to its last complete chunk.
//
// The tracker works incrementally for files that only grow (as McapWriter's
// do): it remembers where its record walk stopped and the SHA-256 state at
// the servable length, so a growing multi-gigabyte log costs only the new
// bytes on each update. A file replaced by another (new inode), shrunk, or
// rewritten in place (the bytes just before the hashed length changed) is
// examined from scratch.

#include <sys/types.h>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/log/archive/sha256.h"

namespace rover::log {

/// What McapServableTracker found.
struct McapServableInfo {
  uint64_t file_size_bytes = 0;        ///< Size of the file when examined.
  uint64_t servable_length_bytes = 0;  ///< Bytes that may be served: [0, servable_length_bytes).
  /// True when the file ends with Footer + magic and McapReader accepts its
  /// summary; then servable_length_bytes == file_size_bytes.
  bool complete = false;
  /// Log times of the earliest and latest message in the servable bytes: from
  /// the summary's Statistics (or chunk indexes) of a complete log, else from
  /// the chunk headers and loose messages of the record walk. Absent when
  /// there are no messages.
  std::optional<uint64_t> start_time_ns;
  std::optional<uint64_t> end_time_ns;
  std::string sha256;  ///< SHA-256 of the servable bytes, lowercase hex.
};

/// Keeps McapServableInfo of one file up to date. Not thread-safe.
class McapServableTracker {
 public:
  /// Examines the regular file open as `fd` (read-only; the tracker neither
  /// closes nor moves its offset) and returns what may be served. `name`
  /// appears in error messages. A file that is not MCAP (wrong magic, no
  /// Header record first) has nothing servable. Throws std::runtime_error if
  /// the file cannot be read.
  const McapServableInfo& Update(int fd, const std::string& name);

  /// Forgets everything: the next Update() starts from byte 0.
  void Reset();

 private:
  struct Walk {
    uint64_t next_offset = 0;  ///< Where the next record starts; 0: magic not checked yet.
    bool header_seen = false;
    bool not_mcap = false;
    std::optional<uint64_t> start_time_ns;
    std::optional<uint64_t> end_time_ns;
  };

  void WalkRecords(int fd, uint64_t file_size_bytes, const std::string& name);
  bool TailSampleMatches(int fd, const std::string& name) const;
  void HashUpTo(int fd, uint64_t length_bytes, const std::string& name);

  bool has_identity_ = false;
  dev_t dev_ = 0;
  ino_t ino_ = 0;
  int64_t mtime_ns_ = -1;  ///< Of the file when info_ was computed.
  bool info_valid_ = false;
  McapServableInfo info_;
  Walk walk_;
  Sha256 sha_;                          ///< Over [0, sha_.size_bytes()).
  std::vector<std::byte> tail_sample_;  ///< The last bytes before sha_.size_bytes().
};

}  // namespace rover::log

#endif  // ROVER_CORE_LOG_ARCHIVE_MCAP_SERVABLE_H_
