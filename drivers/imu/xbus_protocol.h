#ifndef ROVER_DRIVERS_IMU_XBUS_PROTOCOL_H_
#define ROVER_DRIVERS_IMU_XBUS_PROTOCOL_H_

// Xsens Xbus framing ("MT Low Level Communication Protocol"), as spoken by
// the MTi 1/10/100-series over a UART:
//
//   0xFA | BID | MID | LEN | [EXT_LEN_HI EXT_LEN_LO] | payload | CHECKSUM
//
// BID is 0xFF (the "master" address every single device uses), LEN is the
// payload size, or 0xFF followed by a 16-bit big-endian extended length for
// payloads of 255 bytes and more. The checksum makes every byte after the
// preamble (BID up to and including CHECKSUM) sum to 0 mod 256. All
// multi-byte fields, in frames and in MTData2 items, are big-endian.
//
// This header holds the constants and the stateless encode/decode helpers;
// XbusParser finds frames in a byte stream and MtData2Packet decodes the
// measurement payload.

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>

namespace rover::drivers {
namespace xbus {

inline constexpr uint8_t kPreamble = 0xFA;
inline constexpr uint8_t kMasterBusId = 0xFF;
/// LEN value announcing a 2-byte extended length.
inline constexpr uint8_t kExtendedLength = 0xFF;
/// Largest payload an MTi sends or accepts (extended messages).
inline constexpr std::size_t kMaxPayloadBytes = 2048;
/// Preamble, BID, MID, LEN.
inline constexpr std::size_t kHeaderBytes = 4;
/// Preamble, BID, MID, LEN = 0xFF, EXT_LEN (2).
inline constexpr std::size_t kExtendedHeaderBytes = 6;
/// The frame of the largest payload.
inline constexpr std::size_t kMaxFrameBytes = kExtendedHeaderBytes + kMaxPayloadBytes + 1;

/// Message identifiers used by the drivers (a request and its acknowledge
/// differ by one).
namespace mid {
inline constexpr uint8_t kReqDid = 0x00;
inline constexpr uint8_t kDeviceId = 0x01;
inline constexpr uint8_t kGoToMeasurement = 0x10;
inline constexpr uint8_t kGoToMeasurementAck = 0x11;
inline constexpr uint8_t kGoToConfig = 0x30;
inline constexpr uint8_t kGoToConfigAck = 0x31;
inline constexpr uint8_t kMtData2 = 0x36;
inline constexpr uint8_t kWakeUp = 0x3E;
inline constexpr uint8_t kWakeUpAck = 0x3F;
inline constexpr uint8_t kError = 0x42;
inline constexpr uint8_t kSetOutputConfiguration = 0xC0;
inline constexpr uint8_t kSetOutputConfigurationAck = 0xC1;
}  // namespace mid

/// MTData2 data identifiers (float32, ENU where a frame applies).
namespace data_id {
inline constexpr uint16_t kPacketCounter = 0x1020;   ///< uint16
inline constexpr uint16_t kSampleTimeFine = 0x1060;  ///< uint32, 10 kHz ticks
inline constexpr uint16_t kAcceleration = 0x4020;    ///< 3 x float32, m/s^2
inline constexpr uint16_t kRateOfTurn = 0x8020;      ///< 3 x float32, rad/s
}  // namespace data_id

/// SetOutputConfiguration frequency meaning "with every packet" (used for
/// counters and time stamps, which have no rate of their own).
inline constexpr uint16_t kEveryPacket = 0xFFFF;
/// SampleTimeFine counts at 10 kHz.
inline constexpr int64_t kSampleTimeFineHz = 10'000;

/// Error codes of the Error (0x42) message that the drivers name.
namespace error_code {
inline constexpr uint8_t kInvalidPeriod = 0x03;
inline constexpr uint8_t kInvalidMessage = 0x04;
}  // namespace error_code

/// A human-readable name of an Error message code ("invalid period"), or
/// "unknown error" for codes this driver does not name.
const char* ErrorCodeName(uint8_t code);

/// One received frame. `payload` points into the parser's buffer and stays
/// valid until the parser is fed or asked for the next frame.
struct Message {
  uint8_t bus_id = kMasterBusId;
  uint8_t mid = 0;
  std::span<const uint8_t> payload;
};

/// Bytes of the frame that carries `payload_bytes` bytes.
constexpr std::size_t FrameBytes(std::size_t payload_bytes) {
  return (payload_bytes < kExtendedLength ? kHeaderBytes : kExtendedHeaderBytes) + payload_bytes +
         1;
}

/// The checksum byte that makes `bytes` (BID onwards, without the checksum)
/// plus that byte sum to 0 mod 256.
uint8_t Checksum(std::span<const uint8_t> bytes);

/// Writes the frame of (bus_id, mid, payload) to the start of `out`.
/// Returns the frame size, or 0 (nothing written) if the payload is longer
/// than kMaxPayloadBytes or `out` is too small. Never allocates.
std::size_t EncodeMessage(uint8_t bus_id, uint8_t mid, std::span<const uint8_t> payload,
                          std::span<uint8_t> out);
/// EncodeMessage to the master bus id 0xFF.
inline std::size_t EncodeMessage(uint8_t mid, std::span<const uint8_t> payload,
                                 std::span<uint8_t> out) {
  return EncodeMessage(kMasterBusId, mid, payload, out);
}

// Big-endian field access. The caller guarantees the bounds.
inline uint16_t ReadU16(const uint8_t* p) {
  return static_cast<uint16_t>((static_cast<unsigned>(p[0]) << 8) | p[1]);
}
inline uint32_t ReadU32(const uint8_t* p) {
  return (static_cast<uint32_t>(p[0]) << 24) | (static_cast<uint32_t>(p[1]) << 16) |
         (static_cast<uint32_t>(p[2]) << 8) | static_cast<uint32_t>(p[3]);
}
inline float ReadF32(const uint8_t* p) {
  const uint32_t bits = ReadU32(p);
  float value = 0.0f;
  std::memcpy(&value, &bits, sizeof value);
  return value;
}
inline void WriteU16(uint16_t v, uint8_t* p) {
  p[0] = static_cast<uint8_t>(v >> 8);
  p[1] = static_cast<uint8_t>(v);
}
inline void WriteU32(uint32_t v, uint8_t* p) {
  p[0] = static_cast<uint8_t>(v >> 24);
  p[1] = static_cast<uint8_t>(v >> 16);
  p[2] = static_cast<uint8_t>(v >> 8);
  p[3] = static_cast<uint8_t>(v);
}
inline void WriteF32(float v, uint8_t* p) {
  uint32_t bits = 0;
  std::memcpy(&bits, &v, sizeof bits);
  WriteU32(bits, p);
}

}  // namespace xbus
}  // namespace rover::drivers

#endif  // ROVER_DRIVERS_IMU_XBUS_PROTOCOL_H_
