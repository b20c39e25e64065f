#ifndef ROVER_DRIVERS_GPIO_GPIO_EDGE_H_
#define ROVER_DRIVERS_GPIO_GPIO_EDGE_H_

#include <cstdint>

#include "core/time/time.h"

namespace rover::drivers {

/// An edge on a GPIO line (camera trigger, IMU data-ready, PPS) with its
/// kernel timestamp.
struct GpioEdge {
  Time stamp;
  uint32_t line = 0;
  bool rising = true;
};

}  // namespace rover::drivers

#endif  // ROVER_DRIVERS_GPIO_GPIO_EDGE_H_
