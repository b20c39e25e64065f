#ifndef ROVER_DRIVERS_IMU_XBUS_PARSER_H_
#define ROVER_DRIVERS_IMU_XBUS_PARSER_H_

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>

#include "drivers/imu/xbus_protocol.h"

namespace rover::drivers {

/// What the parser threw away, for the driver's health counters.
struct XbusParserStats {
  uint64_t frames = 0;           ///< valid frames handed out
  uint64_t garbage_bytes = 0;    ///< bytes dropped while looking for a frame start
  uint64_t checksum_errors = 0;  ///< frame candidates whose checksum failed
  uint64_t oversize_frames = 0;  ///< frame candidates announcing more than the maximum payload
  uint64_t resyncs = 0;          ///< times the parser lost frame alignment and had to search
};

/// Incremental Xbus frame parser over one buffer allocated at construction.
///
/// Bytes go in with Feed() (or zero-copy: read() into WritableSpace(), then
/// Commit()); complete, checksum-verified frames come out of Next(). A frame
/// starts at 0xFA 0xFF. Anything else is garbage: the parser drops it byte by
/// byte until the next 0xFA 0xFF. A candidate whose checksum fails or whose
/// length exceeds the maximum payload loses only its preamble byte, and the
/// search goes on from the byte after it, so a real frame that began inside
/// a corrupted one (a frame cut short by a lost byte) is still found. The
/// result depends only on the byte stream, never on how it was split into
/// Feed() calls.
///
/// After construction nothing allocates, throws or locks: Feed, Next,
/// WritableSpace and Commit are safe on the real-time path.
class XbusParser {
 public:
  /// `max_payload_bytes`: longer announced lengths are impossible (counted
  /// as oversize). The buffer holds two maximum frames so a frame can always
  /// complete behind a partly consumed one.
  explicit XbusParser(std::size_t max_payload_bytes = xbus::kMaxPayloadBytes);
  XbusParser(const XbusParser&) = delete;
  XbusParser& operator=(const XbusParser&) = delete;

  /// Appends as many of `bytes` as fit and returns how many that was. The
  /// buffer always has room for at least one maximum frame after Next()
  /// returned false, so a caller that alternates Feed and Next until Next
  /// fails never loses bytes.
  std::size_t Feed(std::span<const uint8_t> bytes);

  /// Free space behind the buffered bytes, for reading straight into the
  /// parser; follow with Commit(n). Compacts the buffer first if that frees
  /// space.
  std::span<uint8_t> WritableSpace();
  /// Declares that the first `n` bytes of WritableSpace() were filled.
  void Commit(std::size_t n);

  /// Extracts the next valid frame into *message (payload points into the
  /// buffer, valid until the next Feed, Commit, WritableSpace or Next call).
  /// Returns false when the buffered bytes hold no complete frame yet.
  bool Next(xbus::Message* message);

  /// Drops every buffered byte (uncounted) and returns to "in sync".
  void Reset();

  const XbusParserStats& stats() const { return stats_; }
  std::size_t buffered_bytes() const { return end_ - begin_; }
  std::size_t max_payload_bytes() const { return max_payload_bytes_; }

 private:
  void Drop(std::size_t n);  // discard n bytes at begin_ as garbage
  void LoseSync();
  void Compact();

  std::size_t max_payload_bytes_;
  std::size_t capacity_;
  std::unique_ptr<uint8_t[]> buffer_;
  std::size_t begin_ = 0;  // first unconsumed byte
  std::size_t end_ = 0;    // one past the last buffered byte
  bool in_sync_ = true;
  XbusParserStats stats_{};
};

}  // namespace rover::drivers

#endif  // ROVER_DRIVERS_IMU_XBUS_PARSER_H_
