#ifndef ROVER_DRIVERS_CAN_CANOPEN_WHEEL_PROTOCOL_H_
#define ROVER_DRIVERS_CAN_CANOPEN_WHEEL_PROTOCOL_H_

// The motor-controller CAN protocol of the wheel drives (DESIGN.md), as pure
// encode/decode functions, shared by the SocketCAN driver, roverd's wheel
// decoder and the simulator's drives.
//
// CANopen CiA 402 style, classic 11-bit frames:
//   SYNC       id 0x080, no payload, from the bus master at 100 Hz.
//   TPDO1      id 0x180 + node, after every SYNC, 8 bytes little-endian:
//              bytes 0..3 velocity actual value  (int32, 0.001 rad/s, wheel shaft)
//              bytes 4..7 position actual value  (int32, encoder ticks, wraps)
//   heartbeat  id 0x700 + node, 1 Hz, 1 byte NMT state (0x05 operational).
// Node ids: 1 front-left, 2 front-right, 3 rear-left, 4 rear-right. Positive
// velocity and increasing position mean the wheel rolls the rover forward
// (the drives of the right side invert their motor direction).

#include <cstdint>
#include <optional>

#include "core/time/time.h"
#include "drivers/can/can_frame.h"

namespace rover::drivers {

inline constexpr uint32_t kCanSyncId = 0x080;
inline constexpr uint32_t kCanTpdo1BaseId = 0x180;
inline constexpr uint32_t kCanHeartbeatBaseId = 0x700;
inline constexpr uint8_t kNmtOperational = 0x05;
inline constexpr uint8_t kNmtBootUp = 0x00;
inline constexpr uint8_t kWheelNodeCount = 4;  ///< node ids 1..4
inline constexpr double kCanSyncRate_hz = 100.0;
inline constexpr double kCanHeartbeatRate_hz = 1.0;
/// Unit of the velocity actual value.
inline constexpr double kTpdoVelocityUnit_rad_s = 0.001;

/// Contents of one drive's TPDO1.
struct WheelTpdo1 {
  uint8_t node_id = 1;
  int32_t velocity_mrad_s = 0;
  int32_t position_ticks = 0;
};

struct CanHeartbeat {
  uint8_t node_id = 1;
  uint8_t nmt_state = kNmtOperational;
};

/// The SYNC frame (no payload).
CanFrame EncodeSync(Time stamp);
/// TPDO1 of drive `tpdo.node_id` (1..4).
CanFrame EncodeWheelTpdo1(Time stamp, const WheelTpdo1& tpdo);
/// Heartbeat of `heartbeat.node_id` (1..127).
CanFrame EncodeHeartbeat(Time stamp, const CanHeartbeat& heartbeat);

/// True for a SYNC frame (id 0x080; any DLC 0..1, a SYNC counter is allowed).
bool IsSync(const CanFrame& frame);
/// The TPDO1 of a wheel drive (id 0x181..0x184 with DLC 8), else nullopt.
std::optional<WheelTpdo1> DecodeWheelTpdo1(const CanFrame& frame);
/// A heartbeat (id 0x701..0x77F with DLC 1), else nullopt.
std::optional<CanHeartbeat> DecodeHeartbeat(const CanFrame& frame);

/// Rounds a wheel rate to the TPDO unit, saturating at the int32 range.
int32_t VelocityToTpdo(double angular_velocity_rad_s);
/// Low 32 bits of an unbounded tick count, as the drive's position register
/// holds it (two's complement wrap-around).
int32_t WrapTicks(int64_t ticks);

}  // namespace rover::drivers

#endif  // ROVER_DRIVERS_CAN_CANOPEN_WHEEL_PROTOCOL_H_
