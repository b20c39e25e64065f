#ifndef ROVER_DRIVERS_GPIO_GPIO_CHIP_H_
#define ROVER_DRIVERS_GPIO_GPIO_CHIP_H_

// The boundary between the GPIO drivers and the kernel: a chip hands out
// requested lines, an output line sets a level, an event line delivers edges.
// LibgpiodChip implements it on /dev/gpiochipN (libgpiod v1), FakeGpioChip in
// memory for tests. Everything above it (edge sources, the camera trigger,
// the loopback check) is written against this interface only, so it runs
// unchanged on a board and in tests, and no public header needs gpiod.h.

#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>

#include "drivers/gpio/gpio_event_line.h"
#include "drivers/gpio/gpio_output_line.h"

namespace rover::drivers {

/// A start-up failure of a GPIO chip or line. The message names the chip and
/// the line, says what was expected and gives the system error.
class GpioError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Which edges an event line reports.
enum class GpioEdges {
  kRising,   ///< inactive -> active only
  kFalling,  ///< active -> inactive only
  kBoth,     ///< both, so pulses and their widths can be checked
};

/// What a line request asks the kernel for.
struct GpioLineRequest {
  /// Line offset on the chip (the number `gpioinfo` prints).
  uint32_t line = 0;
  /// Who holds the line, as `gpioinfo` shows it (at most 31 characters: the
  /// kernel truncates longer labels).
  std::string consumer = "rover";
  /// Active level is physical low: "high"/"rising" in this API then mean
  /// active/becoming active, and the kernel inverts the physical level.
  bool active_low = false;
};

/// A GPIO chip handing out lines. Requests happen at start-up: they may
/// allocate and throw. The returned lines are used on the real-time path.
/// Lines must not outlive their chip unless the implementation says so.
class GpioChip {
 public:
  virtual ~GpioChip() = default;

  /// Requests `request.line` as an output driven to `initial_active`.
  /// Throws GpioError naming the chip and line if the line does not exist or
  /// is held by another consumer.
  virtual std::unique_ptr<GpioOutputLine> RequestOutput(const GpioLineRequest& request,
                                                        bool initial_active) = 0;

  /// Requests `request.line` as an input reporting `edges` with kernel
  /// timestamps. Throws GpioError naming the chip and line if the line does
  /// not exist, is held by another consumer, or cannot raise interrupts.
  virtual std::unique_ptr<GpioEventLine> RequestEdges(const GpioLineRequest& request,
                                                      GpioEdges edges) = 0;

  /// The chip's name for messages, e.g. "gpiochip0 [pinctrl-bcm2711]".
  virtual const std::string& name() const = 0;
};

}  // namespace rover::drivers

#endif  // ROVER_DRIVERS_GPIO_GPIO_CHIP_H_
