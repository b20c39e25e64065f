#ifndef ROVER_CORE_LOG_CDR_CDR_WRITER_H_
#define ROVER_CORE_LOG_CDR_CDR_WRITER_H_

// Little-endian plain CDR (XCDR1) encoder, byte-compatible with what
// rmw_fastrtps writes for ROS 2 messages.
//
// Layout rules implemented here:
//  * A 4-byte encapsulation header `00 01 00 00` (CDR_LE) precedes the payload.
//  * Every primitive of size n (1, 2, 4, 8) is aligned to n, measured from the
//    first payload byte (i.e. after the header). Padding bytes are written as 0
//    so that output is deterministic and never leaks stale buffer contents.
//  * string: uint32 length including the terminating NUL, the bytes, the NUL.
//  * sequence: uint32 element count, then the elements.
//  * fixed array: the elements only.
//  * bool: one byte, 0 or 1.
//
// The writer is built for the real-time log path: in fixed-buffer mode it never
// allocates and never throws. Running out of space sets a sticky failure flag;
// the writer keeps counting the bytes the message would need so the caller can
// size a retry (see required_size()).

#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

namespace rover::log {

class CdrWriter {
 public:
  /// Size of the encapsulation header that precedes every payload.
  static constexpr size_t kEncapsulationHeaderSize = 4;

  /// Fixed-buffer mode: serialises into `buffer`, starting with the encapsulation
  /// header. Never allocates. If `buffer` is too small, ok() turns false.
  explicit CdrWriter(std::span<std::byte> buffer) noexcept;

  /// Growing mode (host use; allocates): appends the encapsulation header and
  /// then the payload to the end of `*out`, which must outlive the writer.
  /// Alignment is relative to the appended payload, not to the start of `*out`.
  explicit CdrWriter(std::vector<std::byte>* out);

  CdrWriter(const CdrWriter&) = delete;
  CdrWriter& operator=(const CdrWriter&) = delete;

  /// False once any write did not fit the fixed buffer or a length exceeded the
  /// uint32 range of CDR. Sticky: later writes are not stored.
  bool ok() const noexcept { return !failed_; }

  /// Number of valid bytes written, including the encapsulation header. After a
  /// failure this is the length of the valid prefix written before it.
  size_t size() const noexcept { return (failed_ ? fail_pos_ : pos_) - base_; }

  /// Number of bytes the complete message needs, including the header, even if
  /// it did not fit. Equal to size() while ok().
  size_t required_size() const noexcept { return pos_ - base_; }

  /// The bytes written so far (header included). In growing mode the span is
  /// invalidated by the next write.
  std::span<const std::byte> data() const noexcept { return {data_ + base_, size()}; }

  void WriteBool(bool value);
  void WriteU8(uint8_t value);
  void WriteI8(int8_t value);
  void WriteU16(uint16_t value);
  void WriteI16(int16_t value);
  void WriteU32(uint32_t value);
  void WriteI32(int32_t value);
  void WriteU64(uint64_t value);
  void WriteI64(int64_t value);
  void WriteF32(float value);
  void WriteF64(double value);

  /// Writes a CDR string: uint32 (size + 1), the bytes, a NUL. Fails the writer
  /// if the length does not fit in uint32.
  void WriteString(std::string_view value);

  /// Writes the uint32 element count that precedes a sequence's elements.
  /// Fails the writer if `count` does not fit in uint32.
  void WriteSequenceSize(size_t count);

  /// Writes raw octets (the body of a uint8[N] array or uint8[] sequence; the
  /// caller writes the count for sequences).
  void WriteU8Array(std::span<const uint8_t> values);

  /// Writes the elements of a float64 array. Aligns to 8 only when non-empty,
  /// as an empty array has no first element to align.
  void WriteF64Array(std::span<const double> values);

 private:
  // Aligns the write position to `align` (relative to the payload start) and
  // reserves `n` bytes. Returns where to write them, or nullptr if they do not
  // fit (the writer is then failed but keeps counting required bytes).
  std::byte* Reserve(size_t align, size_t n);
  void Fail() noexcept;
  template <typename T>
  void WritePrimitive(T value);

  std::byte* data_ = nullptr;
  size_t capacity_ = 0;                     // Usable bytes at data_ (fixed mode).
  std::vector<std::byte>* grow_ = nullptr;  // Non-null in growing mode.
  size_t base_ = 0;                         // Index of the encapsulation header.
  size_t pos_ = 0;                          // Logical write index (keeps counting after failure).
  size_t fail_pos_ = 0;                     // pos_ when the first failure happened.
  bool failed_ = false;
};

}  // namespace rover::log

#endif  // ROVER_CORE_LOG_CDR_CDR_WRITER_H_
