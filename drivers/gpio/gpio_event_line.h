#ifndef ROVER_DRIVERS_GPIO_GPIO_EVENT_LINE_H_
#define ROVER_DRIVERS_GPIO_GPIO_EVENT_LINE_H_

#include <cstdint>

#include "core/time/time.h"
#include "drivers/gpio/gpio_edge.h"
#include "drivers/read_status.h"

namespace rover::drivers {

/// A requested input line delivering edge events in the order the kernel
/// queued them. Released when destroyed. Read() is real-time safe.
///
/// The kernel (GPIO uAPI v1) queues at most 16 events per line and drops the
/// newest ones when its FIFO is full, silently: v1 events carry no sequence
/// number. Loss detection therefore happens one level up, from the edge
/// pattern and the nominal period (GpioLineEdgeSource).
class GpioEventLine {
 public:
  virtual ~GpioEventLine() = default;

  /// Waits up to `timeout` for the next queued event and stores it in *edge:
  /// the kernel's CLOCK_MONOTONIC timestamp (Linux >= 5.7), the line offset,
  /// and whether the line became active (`rising`). Returns kTimeout if none
  /// arrived (also when interrupted by a signal), kError if the read failed.
  /// No allocation, no lock, never throws.
  virtual ReadStatus Read(GpioEdge* edge, Duration timeout) = 0;

  /// The line offset on its chip.
  virtual uint32_t line() const = 0;
};

}  // namespace rover::drivers

#endif  // ROVER_DRIVERS_GPIO_GPIO_EVENT_LINE_H_
