#ifndef ROVER_DRIVERS_GPIO_LIBGPIOD_CHIP_H_
#define ROVER_DRIVERS_GPIO_LIBGPIOD_CHIP_H_

// A GPIO chip character device (/dev/gpiochipN) through libgpiod v1 (1.6, as
// Debian 12 ships), which speaks the kernel's GPIO uAPI v1.
//
// Timestamps: uAPI v1 edge events are stamped by the kernel in the line's
// interrupt handler with ktime_get_ns(), i.e. CLOCK_MONOTONIC, since Linux
// 5.7 (commit "gpio: Switch timestamps to ktime_get_ns()"); older kernels used
// CLOCK_REALTIME. RequestEdges() therefore refuses kernels older than 5.7, so
// an edge stamp can be compared with Time::Now() and every other sensor stamp.
// With a nested (threaded) interrupt controller, e.g. an I2C GPIO expander,
// the stamp is taken in the interrupt thread and is correspondingly later.
//
// Edge kind: for a both-edges request the v1 kernel reads the line level in
// its interrupt thread to decide rising vs falling; a pulse shorter than that
// thread's latency can be reported with the wrong kind. Keep input pulses
// wider than the board's interrupt latency (tens of microseconds).

#include <cstdint>
#include <memory>
#include <string>

#include "drivers/gpio/gpio_chip.h"

namespace rover::drivers {

class LibgpiodChip final : public GpioChip {
 public:
  /// Opens a chip by `chip`: a path ("/dev/gpiochip0"), a device name
  /// ("gpiochip0") or a chip label as `gpiodetect` prints it
  /// ("pinctrl-bcm2711"). Throws GpioError naming `chip` and the system error
  /// (no such device, no permission: add the user to group gpio or give it a
  /// udev rule).
  explicit LibgpiodChip(const std::string& chip);
  ~LibgpiodChip() override;
  LibgpiodChip(const LibgpiodChip&) = delete;
  LibgpiodChip& operator=(const LibgpiodChip&) = delete;

  /// Requests an output line (gpiod_line_request_output_flags). Throws
  /// GpioError naming the chip, the line, the expected range and the current
  /// holder if the line is busy. The returned line keeps the chip open, so it
  /// may outlive this object.
  std::unique_ptr<GpioOutputLine> RequestOutput(const GpioLineRequest& request,
                                                bool initial_active) override;

  /// Requests an event line (gpiod_line_request_*_edge_events_flags). The
  /// returned line's Read() polls the line's event fd (ppoll, nanosecond
  /// timeout) and reads one event (gpiod_line_event_read_fd): no allocation.
  /// Throws GpioError as RequestOutput(), and also if the running kernel is
  /// older than 5.7 (its event stamps are not on CLOCK_MONOTONIC). The
  /// returned line keeps the chip open.
  std::unique_ptr<GpioEventLine> RequestEdges(const GpioLineRequest& request,
                                              GpioEdges edges) override;

  /// "gpiochip0 [pinctrl-bcm2711]".
  const std::string& name() const override;
  /// Number of lines on the chip.
  uint32_t num_lines() const;

  /// True if a kernel release string ("6.1.0-18-amd64") is at least 5.7, the
  /// first release stamping uAPI v1 events on CLOCK_MONOTONIC. Exposed for
  /// tests.
  static bool KernelStampsAreMonotonic(const std::string& release);

  /// The open chip, shared with the lines it handed out (opaque: defined in
  /// libgpiod_chip.cc so that this header needs no gpiod.h).
  struct Impl;

 private:
  std::shared_ptr<Impl> impl_;
};

}  // namespace rover::drivers

#endif  // ROVER_DRIVERS_GPIO_LIBGPIOD_CHIP_H_
