#ifndef ROVER_CORE_LOG_CDR_CDR_READER_H_
#define ROVER_CORE_LOG_CDR_CDR_READER_H_

// Bounds-checked decoder for little-endian plain CDR (XCDR1), the inverse of
// CdrWriter. Meant for untrusted input (log files from disk, network):
//  * every read checks the remaining bytes and never reads past the span;
//  * sequence counts are checked against the remaining bytes before anything is
//    allocated, so a corrupted count cannot trigger a huge allocation;
//  * the first failure is recorded as a message naming the message type, the
//    field path being read (e.g. "header.frame_id", "status[2].values[0].key")
//    and the byte offset, and every later read fails without touching it.
//
// Offsets in errors and offset() count from the first byte of the span, i.e.
// the encapsulation header is bytes 0..3 and the payload starts at offset 4, so
// they can be matched against a hex dump of the serialized message.

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace rover::log {

class CdrReader {
 public:
  /// Starts reading `data`, which must begin with a CDR_LE encapsulation header
  /// and must outlive the reader. `message_name` (e.g. "sensor_msgs/msg/Imu")
  /// prefixes error messages; it must outlive the reader too. If the header is
  /// missing or not little-endian CDR, the reader starts out failed.
  explicit CdrReader(std::span<const std::byte> data, std::string_view message_name = {});

  CdrReader(const CdrReader&) = delete;
  CdrReader& operator=(const CdrReader&) = delete;

  /// True while no read has failed.
  bool ok() const noexcept { return error_.empty(); }

  /// The first failure, formatted as
  /// "<message>: field '<path>' at offset <n>: <what>"; empty while ok().
  const std::string& error() const noexcept { return error_; }

  /// Offset of the next unread byte from the start of the span.
  size_t offset() const noexcept { return pos_; }

  /// Bytes left after offset().
  size_t remaining() const noexcept { return data_.size() - pos_; }

  /// RAII marker of the field or sequence element being decoded; its name is
  /// part of the path reported in errors. Obtain from EnterField/EnterElement.
  class [[nodiscard]] Scope {
   public:
    Scope(const Scope&) = delete;
    Scope& operator=(const Scope&) = delete;
    ~Scope() { reader_->Pop(); }

   private:
    friend class CdrReader;
    explicit Scope(CdrReader* reader) noexcept : reader_(reader) {}
    CdrReader* reader_;
  };

  /// Appends ".name" to the error path until the returned scope ends. `name`
  /// must stay valid while the scope lives (string literals in practice).
  Scope EnterField(std::string_view name) noexcept;
  /// Appends "[index]" to the error path until the returned scope ends.
  Scope EnterElement(size_t index) noexcept;

  // Primitive reads. `field` names the member being read (appended to the path
  // for error messages); pass "" when the current scope already names it. Each
  // returns false, leaving *out unspecified, once the reader has failed.
  bool ReadBool(std::string_view field, bool* out);  // Rejects bytes other than 0/1.
  bool ReadU8(std::string_view field, uint8_t* out);
  bool ReadI8(std::string_view field, int8_t* out);
  bool ReadU16(std::string_view field, uint16_t* out);
  bool ReadI16(std::string_view field, int16_t* out);
  bool ReadU32(std::string_view field, uint32_t* out);
  bool ReadI32(std::string_view field, int32_t* out);
  bool ReadU64(std::string_view field, uint64_t* out);
  bool ReadI64(std::string_view field, int64_t* out);
  bool ReadF32(std::string_view field, float* out);
  bool ReadF64(std::string_view field, double* out);

  /// Reads a CDR string without copying: *out views the input bytes, excluding
  /// the terminating NUL. A length prefix of 0 is accepted as "" (some writers
  /// emit it); otherwise the last byte must be NUL.
  bool ReadStringView(std::string_view field, std::string_view* out);
  /// As ReadStringView, copied into *out (allocates).
  bool ReadString(std::string_view field, std::string* out);

  /// Reads a sequence's uint32 element count and rejects it if the elements
  /// cannot fit in the remaining bytes, given that each takes at least
  /// `min_element_size` (>= 1) bytes. This bounds any allocation by the input.
  bool ReadSequenceSize(std::string_view field, size_t min_element_size, size_t* count);

  /// Reads a uint8[] sequence (count + octets) into *out.
  bool ReadU8Sequence(std::string_view field, std::vector<uint8_t>* out);

  /// Reads the elements of a fixed-size float64 array (no count prefix).
  bool ReadF64Array(std::string_view field, std::span<double> out);

  /// Decodes a nested message with `Deserialize(CdrReader&, T*)`, found by
  /// argument-dependent lookup, under the path segment `field`.
  template <typename T>
  bool ReadNested(std::string_view field, T* out) {
    const Scope scope = EnterField(field);
    return ok() && Deserialize(*this, out);
  }

  /// Decodes a sequence of nested messages (count + elements) into *out. The
  /// count is validated with ReadSequenceSize using `min_element_size`; every
  /// ROS message element takes at least 4 bytes unless all its members are
  /// 1-byte primitives, hence the default.
  template <typename T>
  bool ReadSequence(std::string_view field, std::vector<T>* out, size_t min_element_size = 4) {
    const Scope scope = EnterField(field);
    size_t count = 0;
    if (!ReadSequenceSize("", min_element_size, &count)) return false;
    out->clear();
    out->resize(count);
    for (size_t i = 0; i < count; ++i) {
      const Scope element = EnterElement(i);
      if (!Deserialize(*this, &(*out)[i])) return false;
    }
    return true;
  }

  /// Records a failure at byte `at` under the current path (and `field` below
  /// it when non-empty) with description `what`, unless a failure was already
  /// recorded. Always returns false so callers can `return r.Fail(...)`.
  bool Fail(size_t at, std::string_view field, std::string_view what);

 private:
  struct PathSegment {
    std::string_view name;  // Field name (skipped in the path when empty).
    size_t index = 0;       // Element index, when is_index.
    bool is_index = false;
  };
  // Deeper nesting than this is still decoded but elided from error paths.
  static constexpr size_t kMaxPathDepth = 16;

  void Push(PathSegment segment) noexcept;
  std::string FormatPath(std::string_view leaf) const;
  void Pop() noexcept { --depth_; }
  // Aligns to `align` relative to the payload start and checks that `n` bytes
  // follow. On success returns the offset of those bytes and consumes them.
  bool Take(std::string_view field, size_t align, size_t n, std::string_view what, size_t* at);
  template <typename T>
  bool ReadPrimitive(std::string_view field, std::string_view what, T* out);

  std::span<const std::byte> data_;
  std::string_view message_name_;
  size_t pos_ = 0;
  std::array<PathSegment, kMaxPathDepth> path_{};
  size_t depth_ = 0;
  std::string error_;
};

}  // namespace rover::log

#endif  // ROVER_CORE_LOG_CDR_CDR_READER_H_
