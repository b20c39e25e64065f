#include "core/log/cdr/cdr_writer.h"

#include <algorithm>
#include <bit>
#include <cstring>
#include <limits>

namespace rover::log {
namespace {

// CDR_LE encapsulation: representation identifier 0x0001, options 0x0000.
constexpr std::byte kEncapsulationHeader[CdrWriter::kEncapsulationHeaderSize] = {
    std::byte{0x00}, std::byte{0x01}, std::byte{0x00}, std::byte{0x00}};

// Copies `value` into `out` in little-endian byte order.
template <typename T>
void StoreLittleEndian(T value, std::byte* out) noexcept {
  std::memcpy(out, &value, sizeof(T));
  if constexpr (std::endian::native == std::endian::big) {
    std::reverse(out, out + sizeof(T));
  }
}

}  // namespace

CdrWriter::CdrWriter(std::span<std::byte> buffer) noexcept
    : data_(buffer.data()), capacity_(buffer.size()) {
  if (capacity_ < kEncapsulationHeaderSize) {
    Fail();  // Nothing valid was written.
    pos_ = kEncapsulationHeaderSize;
    return;
  }
  std::memcpy(data_, kEncapsulationHeader, kEncapsulationHeaderSize);
  pos_ = kEncapsulationHeaderSize;
}

CdrWriter::CdrWriter(std::vector<std::byte>* out) : grow_(out), base_(out->size()) {
  out->insert(out->end(), std::begin(kEncapsulationHeader), std::end(kEncapsulationHeader));
  data_ = out->data();
  capacity_ = out->size();
  pos_ = capacity_;
}

void CdrWriter::Fail() noexcept {
  if (!failed_) {
    failed_ = true;
    fail_pos_ = pos_;
  }
}

std::byte* CdrWriter::Reserve(size_t align, size_t n) {
  // Alignment is measured from the first payload byte; `align` is a power of 2.
  const size_t payload_offset = pos_ - base_ - kEncapsulationHeaderSize;
  const size_t padding = (align - (payload_offset & (align - 1))) & (align - 1);
  const size_t begin = pos_ + padding;
  const size_t end = begin + n;
  if (failed_) {
    pos_ = end;
    return nullptr;
  }
  if (end > capacity_) {
    if (grow_ == nullptr) {
      Fail();
      pos_ = end;
      return nullptr;
    }
    grow_->resize(end);
    data_ = grow_->data();
    capacity_ = grow_->size();
  }
  std::fill(data_ + pos_, data_ + begin, std::byte{0});
  pos_ = end;
  return data_ + begin;
}

template <typename T>
void CdrWriter::WritePrimitive(T value) {
  if (std::byte* out = Reserve(sizeof(T), sizeof(T)); out != nullptr) {
    StoreLittleEndian(value, out);
  }
}

void CdrWriter::WriteBool(bool value) { WritePrimitive<uint8_t>(value ? 1 : 0); }
void CdrWriter::WriteU8(uint8_t value) { WritePrimitive(value); }
void CdrWriter::WriteI8(int8_t value) { WritePrimitive(value); }
void CdrWriter::WriteU16(uint16_t value) { WritePrimitive(value); }
void CdrWriter::WriteI16(int16_t value) { WritePrimitive(value); }
void CdrWriter::WriteU32(uint32_t value) { WritePrimitive(value); }
void CdrWriter::WriteI32(int32_t value) { WritePrimitive(value); }
void CdrWriter::WriteU64(uint64_t value) { WritePrimitive(value); }
void CdrWriter::WriteI64(int64_t value) { WritePrimitive(value); }
void CdrWriter::WriteF32(float value) { WritePrimitive(value); }
void CdrWriter::WriteF64(double value) { WritePrimitive(value); }

void CdrWriter::WriteString(std::string_view value) {
  // The length prefix counts the terminating NUL, so the longest string is one
  // byte shorter than the uint32 range.
  if (value.size() >= std::numeric_limits<uint32_t>::max()) {
    Fail();
    return;
  }
  const auto length = static_cast<uint32_t>(value.size() + 1);
  if (std::byte* out = Reserve(4, 4 + value.size() + 1); out != nullptr) {
    StoreLittleEndian(length, out);
    if (!value.empty()) std::memcpy(out + 4, value.data(), value.size());
    out[4 + value.size()] = std::byte{0};
  }
}

void CdrWriter::WriteSequenceSize(size_t count) {
  if (count > std::numeric_limits<uint32_t>::max()) {
    Fail();
    return;
  }
  WriteU32(static_cast<uint32_t>(count));
}

void CdrWriter::WriteU8Array(std::span<const uint8_t> values) {
  if (std::byte* out = Reserve(1, values.size()); out != nullptr && !values.empty()) {
    std::memcpy(out, values.data(), values.size());
  }
}

void CdrWriter::WriteF64Array(std::span<const double> values) {
  if (values.empty()) return;
  std::byte* out = Reserve(8, values.size() * sizeof(double));
  if (out == nullptr) return;
  if constexpr (std::endian::native == std::endian::little) {
    std::memcpy(out, values.data(), values.size() * sizeof(double));
  } else {
    for (const double v : values) {
      StoreLittleEndian(v, out);
      out += sizeof(double);
    }
  }
}

}  // namespace rover::log
