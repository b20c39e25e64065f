#ifndef ROVER_DRIVERS_CAN_WHEEL_SPEED_DECODER_H_
#define ROVER_DRIVERS_CAN_WHEEL_SPEED_DECODER_H_

// Streaming decoder of the wheel drives' CANopen traffic (DESIGN.md protocol,
// canopen_wheel_protocol.h): each SYNC opens a period; when the TPDO1s of all
// four drives of that period have arrived, the four wheel rates are emitted,
// stamped with the SYNC's receive time (the drives latch their values on it).
// A period that the next SYNC closes before all four arrived is counted as
// incomplete and emits nothing. Heartbeats are tracked per drive, so a drive
// that stops talking is reported after a timeout. No allocation; one thread.

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "core/time/time.h"
#include "drivers/can/can_frame.h"

namespace rover::drivers {

/// The four wheel rates of one SYNC period (FL, FR, RL, RR = nodes 1..4).
struct WheelSpeeds {
  Time stamp;  ///< the SYNC's receive time
  std::array<double, 4> wheel_rate_rad_s{};
};

struct WheelSpeedDecoderStats {
  uint64_t syncs = 0;
  uint64_t complete = 0;    ///< periods emitted
  uint64_t incomplete = 0;  ///< periods closed with a drive missing
  uint64_t tpdos = 0;
  uint64_t heartbeats = 0;
  uint64_t ignored = 0;  ///< other frames, and TPDO1s before the first SYNC
};

class WheelSpeedDecoder {
 public:
  /// A drive whose last heartbeat is older than `heartbeat_timeout` is
  /// reported missing (the drives send one per second).
  explicit WheelSpeedDecoder(Duration heartbeat_timeout = Duration::Milliseconds(2500))
      : heartbeat_timeout_(heartbeat_timeout) {}

  /// Feeds one frame (in receive order); returns the period's speeds when
  /// this frame completes it.
  std::optional<WheelSpeeds> Feed(const CanFrame& frame);

  /// Bit i set: drive i+1 has sent no heartbeat within the timeout before
  /// `now` (or none at all).
  uint8_t MissingDrives(Time now) const;

  const WheelSpeedDecoderStats& stats() const { return stats_; }

 private:
  Duration heartbeat_timeout_;
  WheelSpeeds current_;
  std::array<bool, 4> seen_{};
  bool open_ = false;
  std::array<std::optional<Time>, 4> last_heartbeat_;
  WheelSpeedDecoderStats stats_;
};

/// Decodes a whole recorded frame stream (in receive order) into the wheel
/// speeds of its complete SYNC periods, as a live decoder would have emitted
/// them; other frames (heartbeats) are ignored.
std::vector<WheelSpeeds> DecodeWheelSpeeds(const std::vector<CanFrame>& frames);

}  // namespace rover::drivers

#endif  // ROVER_DRIVERS_CAN_WHEEL_SPEED_DECODER_H_
