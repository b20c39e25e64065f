#ifndef ROVER_DRIVERS_GPIO_GPIO_LOOPBACK_CHECK_H_
#define ROVER_DRIVERS_GPIO_GPIO_LOOPBACK_CHECK_H_

// A board self-test of the GPIO path roverd uses: with a wire from an output
// line to an input line, pulse the output through GpioCameraTrigger (the
// camera trigger's own code and timing) and read the input through
// GpioLineEdgeSource (the data-ready path's own code), then check every edge
// arrived and report how the kernel's edge stamps relate to the trigger's
// stamps. rover-gpio-loopback (hil/board_check) runs it on a board; the tests
// run it on a FakeGpioChip with a simulated wire.

#include <cstdint>
#include <string>

#include "core/time/time.h"
#include "drivers/gpio/gpio_chip.h"

namespace rover::drivers {

/// What to pulse and how.
struct GpioLoopbackOptions {
  /// Output line offset (driven).
  uint32_t output_line = 0;
  /// Input line offset (wired to the output).
  uint32_t input_line = 1;
  /// Pulses to send, in [1, 1'000'000].
  uint32_t pulses = 100;
  /// Pulse rate, in [1, 100] Hz (GpioCameraTriggerOptions::rate_hz).
  double rate_hz = 10.0;
  /// Active time of each pulse, in (0, period).
  Duration pulse_width = Duration::Milliseconds(1);
  /// Both lines are active low (the wire carries a low-going pulse).
  bool active_low = false;
  /// How long each edge may take to show up at the input, > 0.
  Duration edge_timeout = Duration::Milliseconds(100);
  /// Largest acceptable rising-edge latency; zero = report only.
  Duration max_latency = Duration::Zero();

  /// Throws std::invalid_argument "GpioLoopbackOptions.<field>: expected
  /// ..., found ..." for the first field out of range (see each field).
  void Validate() const;
};

/// What a loopback run saw.
struct GpioLoopbackReport {
  GpioLoopbackOptions options;
  uint32_t pulses = 0;            ///< pulses the trigger emitted
  uint64_t rising_edges = 0;      ///< rising edges matched to a pulse
  uint64_t falling_edges = 0;     ///< falling edges matched to a pulse
  uint64_t missing_edges = 0;     ///< pulse edges that never arrived within edge_timeout
  uint64_t unexpected_edges = 0;  ///< edges of the wrong kind, duplicated or stale
  uint64_t lost_edges = 0;        ///< the edge source's estimate (pattern and period)
  uint64_t skipped_pulses = 0;    ///< trigger slots skipped (the check itself fell behind)
  uint64_t trigger_failures = 0;  ///< Next() calls that did not emit a pulse
  uint64_t read_errors = 0;       ///< input reads that failed
  /// Rising edge's kernel stamp minus the trigger's stamp (taken after the
  /// set ioctl returned, so slightly negative values are normal).
  Duration latency_min;
  Duration latency_p50;
  Duration latency_p99;
  Duration latency_max;
  /// Pulse width seen at the input (falling minus rising kernel stamp).
  Duration width_min;
  Duration width_max;

  /// True if every pulse was emitted and both its edges arrived, nothing
  /// unexpected or lost was seen, no read failed, and the latency stayed
  /// within options.max_latency (if set).
  bool passed() const;
  /// A multi-line human-readable summary ending in "PASS" or "FAIL: why".
  std::string ToString() const;
};

class GpioLoopbackCheck {
 public:
  /// Validates `options` and, when both chips are the same object, that
  /// the two lines differ (std::invalid_argument naming the field).
  GpioLoopbackCheck(GpioChip& output_chip, GpioChip& input_chip,
                    const GpioLoopbackOptions& options);

  /// Requests both lines (GpioError naming chip and line), sends the pulses
  /// and returns what arrived. Takes about pulses / rate_hz seconds, plus
  /// edge_timeout for each missing edge. Start-up code: allocates.
  GpioLoopbackReport Run();

 private:
  GpioChip& output_chip_;
  GpioChip& input_chip_;
  GpioLoopbackOptions options_;
};

}  // namespace rover::drivers

#endif  // ROVER_DRIVERS_GPIO_GPIO_LOOPBACK_CHECK_H_
