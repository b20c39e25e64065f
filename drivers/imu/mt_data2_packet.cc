#include "drivers/imu/mt_data2_packet.h"

#include "drivers/imu/xbus_protocol.h"

namespace rover::drivers {
namespace {

constexpr std::size_t kItemHeaderBytes = 3;  // data id (2) + size (1)

void ReadVector(const uint8_t* p, std::array<float, 3>* v) {
  for (std::size_t i = 0; i < 3; ++i) (*v)[i] = xbus::ReadF32(p + 4 * i);
}

uint8_t* WriteItemHeader(uint16_t id, uint8_t size, uint8_t* p) {
  xbus::WriteU16(id, p);
  p[2] = size;
  return p + kItemHeaderBytes;
}

}  // namespace

bool DecodeMtData2(std::span<const uint8_t> payload, MtData2Packet* packet) {
  *packet = MtData2Packet{};
  std::size_t i = 0;
  while (i < payload.size()) {
    if (payload.size() - i < kItemHeaderBytes) return false;
    const uint8_t* item = payload.data() + i;
    const uint16_t id = xbus::ReadU16(item);
    const std::size_t size = item[2];
    if (payload.size() - i - kItemHeaderBytes < size) return false;
    const uint8_t* data = item + kItemHeaderBytes;
    switch (id) {
      case xbus::data_id::kPacketCounter:
        if (size != 2) return false;
        packet->packet_counter = xbus::ReadU16(data);
        packet->has_packet_counter = true;
        break;
      case xbus::data_id::kSampleTimeFine:
        if (size != 4) return false;
        packet->sample_time_fine = xbus::ReadU32(data);
        packet->has_sample_time_fine = true;
        break;
      case xbus::data_id::kAcceleration:
        if (size != 12) return false;
        ReadVector(data, &packet->acceleration_m_s2);
        packet->has_acceleration = true;
        break;
      case xbus::data_id::kRateOfTurn:
        if (size != 12) return false;
        ReadVector(data, &packet->rate_of_turn_rad_s);
        packet->has_rate_of_turn = true;
        break;
      default:
        break;  // an item this driver does not use
    }
    i += kItemHeaderBytes + size;
  }
  return true;
}

std::size_t EncodeMtData2(const MtData2Packet& packet, std::span<uint8_t> out) {
  std::size_t needed = 0;
  if (packet.has_packet_counter) needed += kItemHeaderBytes + 2;
  if (packet.has_sample_time_fine) needed += kItemHeaderBytes + 4;
  if (packet.has_acceleration) needed += kItemHeaderBytes + 12;
  if (packet.has_rate_of_turn) needed += kItemHeaderBytes + 12;
  if (out.size() < needed) return 0;
  uint8_t* p = out.data();
  if (packet.has_packet_counter) {
    p = WriteItemHeader(xbus::data_id::kPacketCounter, 2, p);
    xbus::WriteU16(packet.packet_counter, p);
    p += 2;
  }
  if (packet.has_sample_time_fine) {
    p = WriteItemHeader(xbus::data_id::kSampleTimeFine, 4, p);
    xbus::WriteU32(packet.sample_time_fine, p);
    p += 4;
  }
  if (packet.has_acceleration) {
    p = WriteItemHeader(xbus::data_id::kAcceleration, 12, p);
    for (std::size_t i = 0; i < 3; ++i) xbus::WriteF32(packet.acceleration_m_s2[i], p + 4 * i);
    p += 12;
  }
  if (packet.has_rate_of_turn) {
    p = WriteItemHeader(xbus::data_id::kRateOfTurn, 12, p);
    for (std::size_t i = 0; i < 3; ++i) xbus::WriteF32(packet.rate_of_turn_rad_s[i], p + 4 * i);
    p += 12;
  }
  return needed;
}

}  // namespace rover::drivers
