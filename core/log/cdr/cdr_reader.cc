#include "core/log/cdr/cdr_reader.h"

#include <algorithm>
#include <bit>
#include <cinttypes>
#include <cstdarg>
#include <cstdio>
#include <cstring>

namespace rover::log {
namespace {

constexpr size_t kHeaderSize = 4;

template <typename T>
T LoadLittleEndian(const std::byte* in) noexcept {
  std::byte bytes[sizeof(T)];
  std::memcpy(bytes, in, sizeof(T));
  if constexpr (std::endian::native == std::endian::big) {
    std::reverse(bytes, bytes + sizeof(T));
  }
  T value;
  std::memcpy(&value, bytes, sizeof(T));
  return value;
}

// printf-style formatting for error messages (only built on failure).
[[gnu::format(printf, 1, 2)]] std::string Format(const char* format, ...) {
  char buffer[192];
  va_list args;
  va_start(args, format);
  std::vsnprintf(buffer, sizeof buffer, format, args);
  va_end(args);
  return buffer;
}

}  // namespace

CdrReader::CdrReader(std::span<const std::byte> data, std::string_view message_name)
    : data_(data), message_name_(message_name) {
  if (data_.size() < kHeaderSize) {
    Fail(0, "",
         Format("buffer of %zu bytes is too short for the 4-byte CDR encapsulation header",
                data_.size()));
    return;
  }
  const auto kind = static_cast<unsigned>(std::to_integer<unsigned>(data_[0]) << 8 |
                                          std::to_integer<unsigned>(data_[1]));
  if (kind != 0x0001) {
    Fail(0, "",
         kind == 0x0000
             ? std::string("big-endian CDR (encapsulation 0x0000) is not supported")
             : Format("unsupported encapsulation 0x%04x; expected 0x0001 (little-endian CDR)",
                      kind));
    return;
  }
  // Bytes 2-3 are encapsulation options (unused by XCDR1 readers).
  pos_ = kHeaderSize;
}

CdrReader::Scope CdrReader::EnterField(std::string_view name) noexcept {
  Push({name, 0, false});
  return Scope(this);
}

CdrReader::Scope CdrReader::EnterElement(size_t index) noexcept {
  Push({{}, index, true});
  return Scope(this);
}

void CdrReader::Push(PathSegment segment) noexcept {
  if (depth_ < kMaxPathDepth) path_[depth_] = segment;
  ++depth_;
}

std::string CdrReader::FormatPath(std::string_view leaf) const {
  std::string path;
  auto append_name = [&path](std::string_view name) {
    if (name.empty()) return;
    if (!path.empty()) path += '.';
    path += name;
  };
  for (size_t i = 0; i < std::min(depth_, kMaxPathDepth); ++i) {
    if (path_[i].is_index) {
      path += '[';
      path += std::to_string(path_[i].index);
      path += ']';
    } else {
      append_name(path_[i].name);
    }
  }
  if (depth_ > kMaxPathDepth) append_name("...");
  append_name(leaf);
  return path;
}

bool CdrReader::Fail(size_t at, std::string_view field, std::string_view what) {
  if (!error_.empty()) return false;
  std::string message;
  if (!message_name_.empty()) {
    message += message_name_;
    message += ": ";
  }
  if (const std::string path = FormatPath(field); !path.empty()) {
    message += "field '";
    message += path;
    message += "' ";
  }
  message += "at offset ";
  message += std::to_string(at);
  message += ": ";
  message += what;
  error_ = std::move(message);
  return false;
}

bool CdrReader::Take(std::string_view field, size_t align, size_t n, std::string_view what,
                     size_t* at) {
  if (!ok()) return false;
  // Alignment counts from the payload start; `align` is a power of two.
  const size_t payload_offset = pos_ - kHeaderSize;
  const size_t padding = (align - (payload_offset & (align - 1))) & (align - 1);
  const size_t left = remaining();
  if (padding > left || n > left - padding) {
    // Report where the value would start, even if its padding runs past the end.
    const size_t begin = pos_ + padding;
    return Fail(
        begin, field,
        Format("truncated: %.*s needs %zu bytes, %zu remaining", static_cast<int>(what.size()),
               what.data(), n, begin < data_.size() ? data_.size() - begin : 0));
  }
  *at = pos_ + padding;
  pos_ = *at + n;
  return true;
}

template <typename T>
bool CdrReader::ReadPrimitive(std::string_view field, std::string_view what, T* out) {
  size_t at = 0;
  if (!Take(field, sizeof(T), sizeof(T), what, &at)) return false;
  *out = LoadLittleEndian<T>(data_.data() + at);
  return true;
}

bool CdrReader::ReadBool(std::string_view field, bool* out) {
  uint8_t value = 0;
  if (!ReadPrimitive(field, "bool", &value)) return false;
  if (value > 1) {
    return Fail(pos_ - 1, field,
                Format("invalid bool value %u (expected 0 or 1)", static_cast<unsigned>(value)));
  }
  *out = value == 1;
  return true;
}

bool CdrReader::ReadU8(std::string_view field, uint8_t* out) {
  return ReadPrimitive(field, "uint8", out);
}
bool CdrReader::ReadI8(std::string_view field, int8_t* out) {
  return ReadPrimitive(field, "int8", out);
}
bool CdrReader::ReadU16(std::string_view field, uint16_t* out) {
  return ReadPrimitive(field, "uint16", out);
}
bool CdrReader::ReadI16(std::string_view field, int16_t* out) {
  return ReadPrimitive(field, "int16", out);
}
bool CdrReader::ReadU32(std::string_view field, uint32_t* out) {
  return ReadPrimitive(field, "uint32", out);
}
bool CdrReader::ReadI32(std::string_view field, int32_t* out) {
  return ReadPrimitive(field, "int32", out);
}
bool CdrReader::ReadU64(std::string_view field, uint64_t* out) {
  return ReadPrimitive(field, "uint64", out);
}
bool CdrReader::ReadI64(std::string_view field, int64_t* out) {
  return ReadPrimitive(field, "int64", out);
}
bool CdrReader::ReadF32(std::string_view field, float* out) {
  return ReadPrimitive(field, "float32", out);
}
bool CdrReader::ReadF64(std::string_view field, double* out) {
  return ReadPrimitive(field, "float64", out);
}

bool CdrReader::ReadStringView(std::string_view field, std::string_view* out) {
  size_t at = 0;
  if (!Take(field, 4, 4, "string length", &at)) return false;
  const auto length = LoadLittleEndian<uint32_t>(data_.data() + at);
  if (length == 0) {
    *out = {};
    return true;
  }
  if (length > remaining()) {
    return Fail(
        at, field,
        Format("string length %" PRIu32 " exceeds remaining %zu bytes", length, remaining()));
  }
  const auto* chars = reinterpret_cast<const char*>(data_.data() + pos_);
  if (chars[length - 1] != '\0') {
    return Fail(at, field, Format("string of length %" PRIu32 " is not NUL-terminated", length));
  }
  *out = std::string_view(chars, length - 1);
  pos_ += length;
  return true;
}

bool CdrReader::ReadString(std::string_view field, std::string* out) {
  std::string_view view;
  if (!ReadStringView(field, &view)) return false;
  out->assign(view);
  return true;
}

bool CdrReader::ReadSequenceSize(std::string_view field, size_t min_element_size, size_t* count) {
  size_t at = 0;
  if (!Take(field, 4, 4, "sequence length", &at)) return false;
  const auto n = LoadLittleEndian<uint32_t>(data_.data() + at);
  const size_t min_size = std::max<size_t>(min_element_size, 1);
  if (n > remaining() / min_size) {
    return Fail(
        at, field,
        min_size == 1
            ? Format("sequence length %" PRIu32 " exceeds remaining %zu bytes", n, remaining())
            : Format("sequence length %" PRIu32
                     " exceeds remaining %zu bytes (elements take at least %zu bytes)",
                     n, remaining(), min_size));
  }
  *count = n;
  return true;
}

bool CdrReader::ReadU8Sequence(std::string_view field, std::vector<uint8_t>* out) {
  size_t count = 0;
  if (!ReadSequenceSize(field, 1, &count)) return false;
  out->resize(count);
  if (count > 0) std::memcpy(out->data(), data_.data() + pos_, count);
  pos_ += count;
  return true;
}

bool CdrReader::ReadF64Array(std::string_view field, std::span<double> out) {
  if (out.empty()) return ok();
  size_t at = 0;
  if (!Take(field, 8, out.size() * sizeof(double), "float64 array", &at)) return false;
  const std::byte* in = data_.data() + at;
  if constexpr (std::endian::native == std::endian::little) {
    std::memcpy(out.data(), in, out.size() * sizeof(double));
  } else {
    for (double& v : out) {
      v = LoadLittleEndian<double>(in);
      in += sizeof(double);
    }
  }
  return true;
}

}  // namespace rover::log
