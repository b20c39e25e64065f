#include "drivers/imu/xbus_protocol.h"

namespace rover::drivers::xbus {

const char* ErrorCodeName(uint8_t code) {
  switch (code) {
    case error_code::kInvalidPeriod:
      return "invalid period";
    case error_code::kInvalidMessage:
      return "invalid or unsupported message";
    default:
      return "unknown error";
  }
}

uint8_t Checksum(std::span<const uint8_t> bytes) {
  unsigned sum = 0;
  for (const uint8_t b : bytes) sum += b;
  return static_cast<uint8_t>(0x100u - (sum & 0xFFu));
}

std::size_t EncodeMessage(uint8_t bus_id, uint8_t mid, std::span<const uint8_t> payload,
                          std::span<uint8_t> out) {
  if (payload.size() > kMaxPayloadBytes) return 0;
  const std::size_t frame_bytes = FrameBytes(payload.size());
  if (out.size() < frame_bytes) return 0;
  uint8_t* p = out.data();
  p[0] = kPreamble;
  p[1] = bus_id;
  p[2] = mid;
  std::size_t header = kHeaderBytes;
  if (payload.size() < kExtendedLength) {
    p[3] = static_cast<uint8_t>(payload.size());
  } else {
    p[3] = kExtendedLength;
    WriteU16(static_cast<uint16_t>(payload.size()), p + 4);
    header = kExtendedHeaderBytes;
  }
  if (!payload.empty()) std::memcpy(p + header, payload.data(), payload.size());
  p[frame_bytes - 1] = Checksum(std::span<const uint8_t>(p + 1, frame_bytes - 2));
  return frame_bytes;
}

}  // namespace rover::drivers::xbus
