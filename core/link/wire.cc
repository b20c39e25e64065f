#include "core/link/wire.h"

#include "core/log/mcap/crc32.h"

namespace rover::link::wire {

uint32_t Crc32(std::span<const uint8_t> bytes) { return log::Crc32(std::as_bytes(bytes)); }

}  // namespace rover::link::wire
