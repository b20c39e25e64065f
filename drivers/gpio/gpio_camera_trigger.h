#ifndef ROVER_DRIVERS_GPIO_GPIO_CAMERA_TRIGGER_H_
#define ROVER_DRIVERS_GPIO_GPIO_CAMERA_TRIGGER_H_

// The stereo head's hardware trigger as a GPIO output pulsed by the camera
// thread itself: Next() sleeps (clock_nanosleep, absolute deadline on
// CLOCK_MONOTONIC) until the next pulse is due, drives the line active,
// stamps the edge, holds it for the pulse width and drives it inactive.
//
// Schedule. Pulse k is due at phase + k * period on CLOCK_MONOTONIC (period =
// 1 / rate_hz rounded to the nanosecond), a fixed grid that does not drift
// with the caller. A caller that arrives after a pulse was due still gets it
// at once if it is at most a quarter period late (counted in late_pulses);
// later than that, every pulse whose time has passed is skipped (counted in
// skipped_pulses) and the next one waits for its own slot, so a stalled
// caller never causes a burst of pulses: successive pulses are scheduled at
// least three quarters of a period apart (cameras must accept 4/3 of rate_hz).
//
// Stamp. The edge time is read right after the set ioctl returns: the pin
// changed inside that call, so the stamp is late by the call's return path
// (a few microseconds; rover-gpio-loopback measures it on a board).

#include <cstdint>
#include <memory>
#include <string>

#include "core/time/time.h"
#include "drivers/camera/camera_trigger.h"
#include "drivers/gpio/gpio_chip.h"
#include "drivers/gpio/gpio_output_line.h"

namespace rover::drivers {

/// The trigger output and its timing (hil/config/gpio.yaml holds the
/// simulated equivalents: camera_rate_hz, camera_phase_s,
/// camera_pulse_width_s, camera_trigger_line).
struct GpioCameraTriggerOptions {
  static constexpr double kMinRateHz = 1.0;
  static constexpr double kMaxRateHz = 100.0;

  /// Pulses per second, in [1, 100].
  double rate_hz = 10.0;
  /// Offset of the pulse grid on CLOCK_MONOTONIC, in [0, period).
  Duration phase = Duration::Zero();
  /// Active time of each pulse, in (0, period).
  Duration pulse_width = Duration::Milliseconds(1);
  /// Line offset on the chip.
  uint32_t line = 17;
  /// The cameras trigger on a low-going pulse.
  bool active_low = false;
  /// Holder name shown by gpioinfo (1 to 31 characters).
  std::string consumer = "rover-camera-trigger";

  /// 1 / rate_hz rounded to the nanosecond; meaningful once validated.
  Duration period() const;
  /// Throws std::invalid_argument "GpioCameraTriggerOptions.<field>: expected
  /// ..., found ..." for the first field out of range (see each field).
  void Validate() const;
};

/// Counters of the trigger. Read them from the thread calling Next().
struct GpioCameraTriggerStats {
  uint64_t pulses = 0;          ///< pulses emitted
  uint64_t skipped_pulses = 0;  ///< grid slots passed over because the caller was late
  uint64_t late_pulses = 0;     ///< pulses emitted after their slot (at most period / 4)
  uint64_t timeouts = 0;        ///< Next() calls that returned kTimeout
  uint64_t set_errors = 0;      ///< set ioctls the kernel refused
};

class GpioCameraTrigger final : public CameraTrigger {
 public:
  /// Validates `options` (std::invalid_argument naming the field) and
  /// requests the line as an output, inactive (GpioError naming the chip
  /// and line). A FakeGpioChip must outlive this object.
  GpioCameraTrigger(GpioChip& chip, const GpioCameraTriggerOptions& options);
  /// Leaves the line inactive.
  ~GpioCameraTrigger() override;
  GpioCameraTrigger(const GpioCameraTrigger&) = delete;
  GpioCameraTrigger& operator=(const GpioCameraTrigger&) = delete;

  /// Emits the next pulse of the grid (see the file comment) and returns
  /// after its falling edge, with the rising edge's CLOCK_MONOTONIC time in
  /// *stamp. If the pulse could not be completed within `timeout` (its slot
  /// plus the pulse width lie beyond it), sleeps for `timeout` and returns
  /// kTimeout; the pulse stays due. kError if the line could not be set
  /// (counted; a line stuck active is retried on the next call). No
  /// allocation, no lock, never throws.
  ReadStatus Next(Time* stamp, Duration timeout) override;

  const GpioCameraTriggerStats& stats() const { return stats_; }
  /// The grid slot of the last pulse emitted (Time::Zero() before the first).
  Time last_deadline() const { return last_deadline_; }
  /// The pulse period.
  Duration period() const { return period_; }
  const GpioCameraTriggerOptions& options() const { return options_; }

 private:
  Time Slot(int64_t index) const;
  // Index of the first slot at or after `t`.
  int64_t FirstSlotAtOrAfter(Time t) const;

  GpioCameraTriggerOptions options_;
  Duration period_;
  std::unique_ptr<GpioOutputLine> line_;
  GpioCameraTriggerStats stats_;
  bool started_ = false;
  bool stuck_active_ = false;
  int64_t next_slot_ = 0;
  Time last_deadline_;
};

}  // namespace rover::drivers

#endif  // ROVER_DRIVERS_GPIO_GPIO_CAMERA_TRIGGER_H_
