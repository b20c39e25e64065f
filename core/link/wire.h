#ifndef ROVER_CORE_LINK_WIRE_H_
#define ROVER_CORE_LINK_WIRE_H_

// Little-endian encoding of the team protocol's datagrams: a writer that
// appends and a reader that refuses to read past the end (a truncated or
// hostile datagram sets failed() instead of reading garbage).

#include <bit>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace rover::link::wire {

class Writer {
 public:
  explicit Writer(std::vector<uint8_t>* out) : out_(out) {}
  void U8(uint8_t v) { out_->push_back(v); }
  void U16(uint16_t v) { Le(v, 2); }
  void U32(uint32_t v) { Le(v, 4); }
  void U64(uint64_t v) { Le(v, 8); }
  void I64(int64_t v) { Le(static_cast<uint64_t>(v), 8); }
  /// IEEE 754 binary64, its bits little-endian.
  void F64(double v) { Le(std::bit_cast<uint64_t>(v), 8); }
  void Bytes(std::span<const uint8_t> b) { out_->insert(out_->end(), b.begin(), b.end()); }
  std::size_t size() const { return out_->size(); }

 private:
  void Le(uint64_t v, int n) {
    for (int i = 0; i < n; ++i) out_->push_back(static_cast<uint8_t>(v >> (8 * i)));
  }
  std::vector<uint8_t>* out_;
};

class Reader {
 public:
  explicit Reader(std::span<const uint8_t> in) : in_(in) {}
  uint8_t U8() { return static_cast<uint8_t>(Le(1)); }
  uint16_t U16() { return static_cast<uint16_t>(Le(2)); }
  uint32_t U32() { return static_cast<uint32_t>(Le(4)); }
  uint64_t U64() { return Le(8); }
  int64_t I64() { return static_cast<int64_t>(Le(8)); }
  double F64() { return std::bit_cast<double>(Le(8)); }
  /// The next `n` bytes (empty and failed() if fewer are left).
  std::span<const uint8_t> Bytes(std::size_t n) {
    if (failed_ || n > in_.size() - pos_) {
      failed_ = true;
      return {};
    }
    const std::span<const uint8_t> b = in_.subspan(pos_, n);
    pos_ += n;
    return b;
  }
  std::size_t remaining() const { return failed_ ? 0 : in_.size() - pos_; }
  bool failed() const { return failed_; }

 private:
  uint64_t Le(std::size_t n) {
    if (failed_ || n > in_.size() - pos_) {
      failed_ = true;
      return 0;
    }
    uint64_t v = 0;
    for (std::size_t i = 0; i < n; ++i) v |= static_cast<uint64_t>(in_[pos_ + i]) << (8 * i);
    pos_ += n;
    return v;
  }
  std::span<const uint8_t> in_;
  std::size_t pos_ = 0;
  bool failed_ = false;
};

/// CRC-32 of `bytes` (MCAP's and zlib's, rover::log::Crc32).
uint32_t Crc32(std::span<const uint8_t> bytes);

}  // namespace rover::link::wire

#endif  // ROVER_CORE_LINK_WIRE_H_
