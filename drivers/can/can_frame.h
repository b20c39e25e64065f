#ifndef ROVER_DRIVERS_CAN_CAN_FRAME_H_
#define ROVER_DRIVERS_CAN_CAN_FRAME_H_

#include <array>
#include <cstdint>

#include "core/time/time.h"

namespace rover::drivers {

/// A classic CAN 2.0A frame with its receive time.
struct CanFrame {
  Time stamp;       ///< kernel RX timestamp (or simulated bus time)
  uint32_t id = 0;  ///< 11-bit identifier
  uint8_t dlc = 0;  ///< payload length, 0..8
  std::array<uint8_t, 8> data{};
};

}  // namespace rover::drivers

#endif  // ROVER_DRIVERS_CAN_CAN_FRAME_H_
