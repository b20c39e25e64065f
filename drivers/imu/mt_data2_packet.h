#ifndef ROVER_DRIVERS_IMU_MT_DATA2_PACKET_H_
#define ROVER_DRIVERS_IMU_MT_DATA2_PACKET_H_

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

namespace rover::drivers {

/// The items of one MTData2 (0x36) payload that the IMU driver uses. The
/// payload is a sequence of (data id: uint16 BE, size: uint8, data) items;
/// each has_* flag says whether its item was present.
struct MtData2Packet {
  bool has_packet_counter = false;
  uint16_t packet_counter = 0;  ///< PacketCounter 0x1020, wraps at 2^16
  bool has_sample_time_fine = false;
  uint32_t sample_time_fine = 0;  ///< SampleTimeFine 0x1060, device ticks at 10 kHz
  bool has_acceleration = false;
  std::array<float, 3> acceleration_m_s2{};  ///< Acceleration 0x4020 (float32)
  bool has_rate_of_turn = false;
  std::array<float, 3> rate_of_turn_rad_s{};  ///< RateOfTurn 0x8020 (float32)

  /// True if all four items are present: what the driver configures.
  bool complete() const {
    return has_packet_counter && has_sample_time_fine && has_acceleration && has_rate_of_turn;
  }
};

/// Decodes an MTData2 payload into *packet (cleared first). Items with other
/// data ids are skipped by their size. Returns false, leaving *packet in an
/// unspecified state, if an item runs past the end of the payload or one of
/// the four known items has an unexpected size. Never allocates.
bool DecodeMtData2(std::span<const uint8_t> payload, MtData2Packet* packet);

/// Writes the present items of `packet` as an MTData2 payload (in the order
/// PacketCounter, SampleTimeFine, Acceleration, RateOfTurn) to the start of
/// `out`. Returns the payload size, or 0 if `out` is too small.
std::size_t EncodeMtData2(const MtData2Packet& packet, std::span<uint8_t> out);

/// Payload size of a complete packet (all four items).
inline constexpr std::size_t kMtData2CompletePayloadBytes = (3 + 2) + (3 + 4) + (3 + 12) + (3 + 12);

}  // namespace rover::drivers

#endif  // ROVER_DRIVERS_IMU_MT_DATA2_PACKET_H_
