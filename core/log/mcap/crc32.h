#ifndef ROVER_CORE_LOG_MCAP_CRC32_H_
#define ROVER_CORE_LOG_MCAP_CRC32_H_

#include <cstddef>
#include <cstdint>
#include <span>

namespace rover::log {

/// CRC-32 as used by MCAP, zlib and Ethernet (reflected polynomial 0xEDB88320,
/// initial value and final XOR 0xFFFFFFFF). Chainable like zlib's crc32():
/// `Crc32(b, Crc32(a))` equals the CRC of `a` followed by `b`, and
/// `Crc32({})` is 0. Crc32 of the ASCII bytes "123456789" is 0xCBF43926.
uint32_t Crc32(std::span<const std::byte> data, uint32_t crc = 0);

}  // namespace rover::log

#endif  // ROVER_CORE_LOG_MCAP_CRC32_H_
