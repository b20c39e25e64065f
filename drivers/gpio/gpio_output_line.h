#ifndef ROVER_DRIVERS_GPIO_GPIO_OUTPUT_LINE_H_
#define ROVER_DRIVERS_GPIO_GPIO_OUTPUT_LINE_H_

#include <cstdint>

namespace rover::drivers {

/// A requested output line (camera trigger, loopback stimulus). Released when
/// destroyed. Set() is real-time safe: one ioctl, no allocation, no lock.
class GpioOutputLine {
 public:
  virtual ~GpioOutputLine() = default;

  /// Drives the line to its active (`true`) or inactive level; with an
  /// active-low request the physical level is the inverse. Returns false if
  /// the kernel refused (the caller counts it); never throws.
  virtual bool Set(bool active) = 0;

  /// The line offset on its chip.
  virtual uint32_t line() const = 0;
};

}  // namespace rover::drivers

#endif  // ROVER_DRIVERS_GPIO_GPIO_OUTPUT_LINE_H_
