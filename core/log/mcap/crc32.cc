#include "core/log/mcap/crc32.h"

#include <zlib.h>

#include <algorithm>
#include <limits>

namespace rover::log {

// MCAP's CRC is zlib's CRC-32 (IEEE 802.3, reflected 0xEDB88320), so zlib's
// optimised implementation computes it directly.
uint32_t Crc32(std::span<const std::byte> data, uint32_t crc) {
  uLong c = crc;
  const auto* p = reinterpret_cast<const Bytef*>(data.data());
  std::size_t n = data.size();
  while (n > 0) {  // zlib takes the length as uInt
    const auto step = static_cast<uInt>(std::min<std::size_t>(n, std::numeric_limits<uInt>::max()));
    c = ::crc32(c, p, step);
    p += step;
    n -= step;
  }
  return static_cast<uint32_t>(c);
}

}  // namespace rover::log
