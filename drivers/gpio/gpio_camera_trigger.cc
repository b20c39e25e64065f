#include "drivers/gpio/gpio_camera_trigger.h"

#include <time.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "core/time/posix_time.h"

namespace rover::drivers {
namespace {

std::string Number(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", value);
  return text;
}

}  // namespace

Duration GpioCameraTriggerOptions::period() const { return Duration::FromSeconds(1.0 / rate_hz); }

void GpioCameraTriggerOptions::Validate() const {
  if (!std::isfinite(rate_hz) || rate_hz < kMinRateHz || rate_hz > kMaxRateHz) {
    throw std::invalid_argument("GpioCameraTriggerOptions.rate_hz: expected " + Number(kMinRateHz) +
                                " to " + Number(kMaxRateHz) + ", found " + Number(rate_hz));
  }
  const Duration p = period();
  if (phase < Duration::Zero() || phase >= p) {
    throw std::invalid_argument("GpioCameraTriggerOptions.phase: expected [0, " + p.ToString() +
                                ") (one period), found " + phase.ToString());
  }
  if (pulse_width <= Duration::Zero() || pulse_width >= p) {
    throw std::invalid_argument("GpioCameraTriggerOptions.pulse_width: expected (0, " +
                                p.ToString() + ") (shorter than the period), found " +
                                pulse_width.ToString());
  }
  if (consumer.empty() || consumer.size() > 31) {
    throw std::invalid_argument(
        "GpioCameraTriggerOptions.consumer: expected 1 to 31 characters, found '" + consumer + "'");
  }
}

namespace {

const GpioCameraTriggerOptions& Validated(const GpioCameraTriggerOptions& options) {
  options.Validate();
  return options;
}

}  // namespace

GpioCameraTrigger::GpioCameraTrigger(GpioChip& chip, const GpioCameraTriggerOptions& options)
    : options_(Validated(options)),
      period_(options.period()),
      line_(chip.RequestOutput(GpioLineRequest{options.line, options.consumer, options.active_low},
                               false)) {}

GpioCameraTrigger::~GpioCameraTrigger() { line_->Set(false); }

Time GpioCameraTrigger::Slot(int64_t index) const {
  return Time::FromNanoseconds(options_.phase.nanoseconds() + index * period_.nanoseconds());
}

int64_t GpioCameraTrigger::FirstSlotAtOrAfter(Time t) const {
  const int64_t offset = t.nanoseconds() - options_.phase.nanoseconds();
  const int64_t p = period_.nanoseconds();
  // Ceiling division that is also right for offsets before the grid origin.
  int64_t index = offset / p;
  if (index * p < offset) ++index;
  return index;
}

ReadStatus GpioCameraTrigger::Next(Time* stamp, Duration timeout) {
  if (timeout < Duration::Zero()) timeout = Duration::Zero();
  if (stuck_active_) {
    if (!line_->Set(false)) {
      ++stats_.set_errors;
      return ReadStatus::kError;
    }
    stuck_active_ = false;
  }
  const Time now = Time::Now();
  if (!started_) {
    next_slot_ = FirstSlotAtOrAfter(now);
    started_ = true;
  }
  Time deadline = Slot(next_slot_);
  if (now - deadline > period_ / 4) {
    // Too late for this slot: pick the next one in the future instead of
    // firing the missed ones back to back.
    const int64_t slot = FirstSlotAtOrAfter(now);
    stats_.skipped_pulses += static_cast<uint64_t>(slot - next_slot_);
    next_slot_ = slot;
    deadline = Slot(slot);
  }
  const Duration until_done =
      (deadline > now ? deadline - now : Duration::Zero()) + options_.pulse_width;
  if (until_done > timeout) {
    SleepUntil(now + timeout);
    ++stats_.timeouts;
    return ReadStatus::kTimeout;
  }
  if (deadline < now) ++stats_.late_pulses;
  SleepUntil(deadline);
  if (!line_->Set(true)) {
    ++stats_.set_errors;
    ++next_slot_;
    return ReadStatus::kError;
  }
  const Time edge = Time::Now();
  SleepUntil(edge + options_.pulse_width);
  if (!line_->Set(false)) {
    // The rising edge did trigger the cameras, so the pulse is reported;
    // the next call drives the line inactive before pulsing again.
    ++stats_.set_errors;
    stuck_active_ = true;
  }
  ++stats_.pulses;
  last_deadline_ = deadline;
  ++next_slot_;
  *stamp = edge;
  return ReadStatus::kOk;
}

}  // namespace rover::drivers
