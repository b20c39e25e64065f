#include "drivers/can/wheel_speed_decoder.h"

#include <algorithm>

#include "drivers/can/canopen_wheel_protocol.h"

namespace rover::drivers {

std::optional<WheelSpeeds> WheelSpeedDecoder::Feed(const CanFrame& frame) {
  if (IsSync(frame)) {
    ++stats_.syncs;
    if (open_) ++stats_.incomplete;  // still open: a drive never answered
    current_ = {};
    current_.stamp = frame.stamp;
    seen_ = {};
    open_ = true;
    return std::nullopt;
  }
  if (const auto tpdo = DecodeWheelTpdo1(frame)) {
    ++stats_.tpdos;
    if (!open_) {
      ++stats_.ignored;
      return std::nullopt;
    }
    const auto i = static_cast<std::size_t>(tpdo->node_id - 1);
    current_.wheel_rate_rad_s[i] = tpdo->velocity_mrad_s * kTpdoVelocityUnit_rad_s;
    seen_[i] = true;
    if (std::all_of(seen_.begin(), seen_.end(), [](bool b) { return b; })) {
      open_ = false;
      ++stats_.complete;
      return current_;
    }
    return std::nullopt;
  }
  if (const auto heartbeat = DecodeHeartbeat(frame)) {
    ++stats_.heartbeats;
    if (heartbeat->node_id >= 1 && heartbeat->node_id <= kWheelNodeCount) {
      last_heartbeat_[static_cast<std::size_t>(heartbeat->node_id - 1)] = frame.stamp;
    }
    return std::nullopt;
  }
  ++stats_.ignored;
  return std::nullopt;
}

uint8_t WheelSpeedDecoder::MissingDrives(Time now) const {
  uint8_t missing = 0;
  for (std::size_t i = 0; i < last_heartbeat_.size(); ++i) {
    if (!last_heartbeat_[i] || now - *last_heartbeat_[i] > heartbeat_timeout_) {
      missing = static_cast<uint8_t>(missing | (1u << i));
    }
  }
  return missing;
}

std::vector<WheelSpeeds> DecodeWheelSpeeds(const std::vector<CanFrame>& frames) {
  std::vector<WheelSpeeds> out;
  WheelSpeedDecoder decoder;
  for (const CanFrame& f : frames) {
    if (const std::optional<WheelSpeeds> speeds = decoder.Feed(f)) out.push_back(*speeds);
  }
  return out;
}

}  // namespace rover::drivers
