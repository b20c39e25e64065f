#include "drivers/can/canopen_wheel_protocol.h"

#include <cmath>
#include <limits>

namespace rover::drivers {
namespace {

void PutInt32(int32_t value, uint8_t* out) {
  const auto u = static_cast<uint32_t>(value);
  for (int i = 0; i < 4; ++i) out[i] = static_cast<uint8_t>(u >> (8 * i));
}

int32_t GetInt32(const uint8_t* in) {
  uint32_t u = 0;
  for (int i = 0; i < 4; ++i) u |= static_cast<uint32_t>(in[i]) << (8 * i);
  return static_cast<int32_t>(u);
}

}  // namespace

CanFrame EncodeSync(Time stamp) {
  CanFrame f;
  f.stamp = stamp;
  f.id = kCanSyncId;
  f.dlc = 0;
  return f;
}

CanFrame EncodeWheelTpdo1(Time stamp, const WheelTpdo1& tpdo) {
  CanFrame f;
  f.stamp = stamp;
  f.id = kCanTpdo1BaseId + tpdo.node_id;
  f.dlc = 8;
  PutInt32(tpdo.velocity_mrad_s, f.data.data());
  PutInt32(tpdo.position_ticks, f.data.data() + 4);
  return f;
}

CanFrame EncodeHeartbeat(Time stamp, const CanHeartbeat& heartbeat) {
  CanFrame f;
  f.stamp = stamp;
  f.id = kCanHeartbeatBaseId + heartbeat.node_id;
  f.dlc = 1;
  f.data[0] = heartbeat.nmt_state;
  return f;
}

bool IsSync(const CanFrame& frame) { return frame.id == kCanSyncId && frame.dlc <= 1; }

std::optional<WheelTpdo1> DecodeWheelTpdo1(const CanFrame& frame) {
  if (frame.id <= kCanTpdo1BaseId || frame.id > kCanTpdo1BaseId + kWheelNodeCount ||
      frame.dlc != 8) {
    return std::nullopt;
  }
  WheelTpdo1 out;
  out.node_id = static_cast<uint8_t>(frame.id - kCanTpdo1BaseId);
  out.velocity_mrad_s = GetInt32(frame.data.data());
  out.position_ticks = GetInt32(frame.data.data() + 4);
  return out;
}

std::optional<CanHeartbeat> DecodeHeartbeat(const CanFrame& frame) {
  if (frame.id <= kCanHeartbeatBaseId || frame.id > kCanHeartbeatBaseId + 0x7F || frame.dlc != 1) {
    return std::nullopt;
  }
  return CanHeartbeat{static_cast<uint8_t>(frame.id - kCanHeartbeatBaseId), frame.data[0]};
}

int32_t VelocityToTpdo(double angular_velocity_rad_s) {
  const double units = std::round(angular_velocity_rad_s / kTpdoVelocityUnit_rad_s);
  constexpr double kMax = std::numeric_limits<int32_t>::max();
  constexpr double kMin = std::numeric_limits<int32_t>::min();
  if (!(units < kMax)) return std::numeric_limits<int32_t>::max();
  if (!(units > kMin)) return std::numeric_limits<int32_t>::min();
  return static_cast<int32_t>(units);
}

int32_t WrapTicks(int64_t ticks) {
  return static_cast<int32_t>(static_cast<uint32_t>(static_cast<uint64_t>(ticks)));
}

}  // namespace rover::drivers
