#ifndef ROVER_DRIVERS_GPIO_GPIO_EDGE_SOURCE_H_
#define ROVER_DRIVERS_GPIO_GPIO_EDGE_SOURCE_H_

#include <cstdint>

#include "core/time/time.h"
#include "drivers/gpio/gpio_edge.h"
#include "drivers/read_status.h"

namespace rover::drivers {

/// Edge events of one requested input line (IMU data-ready, camera sync-out,
/// PPS), each with the kernel's CLOCK_MONOTONIC timestamp. Implementations:
/// a libgpiod v1 line on a real chip, and a fake chip for tests. Wait() is
/// called from real-time threads: no allocation, no locks, blocks at most
/// `timeout`.
class GpioEdgeSource {
 public:
  virtual ~GpioEdgeSource() = default;
  /// Waits up to `timeout` for the next edge; the edge in *edge.
  virtual ReadStatus Wait(GpioEdge* edge, Duration timeout) = 0;
  /// Edges the kernel (or the fake) dropped because they were not read in
  /// time (event FIFO overflow), as far as the implementation can tell.
  virtual uint64_t lost_edges() const = 0;
};

}  // namespace rover::drivers

#endif  // ROVER_DRIVERS_GPIO_GPIO_EDGE_SOURCE_H_
