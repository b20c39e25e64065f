#ifndef ROVER_FIRMWARE_RUNTIME_RT_PERIODIC_TIMER_H_
#define ROVER_FIRMWARE_RUNTIME_RT_PERIODIC_TIMER_H_

// Absolute-deadline periodic wake-up for real-time loops.
//
// Deadlines lie on a fixed grid, first_deadline + k * period, on
// CLOCK_MONOTONIC, and the timer sleeps with
// clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME), so neither wake-up latency
// nor the loop's own work makes the phase drift (a relative sleep would add
// both to every period).
//
// Overruns: when the loop comes back after its next deadline has already
// passed, it runs at once, without sleeping, for the latest grid slot that
// has passed (Tick::slept is false: its lateness is the loop's own overrun,
// not a scheduling latency), and every earlier slot that passed unserved is
// counted as missed. The loop therefore never bursts to catch up, stays on
// its original phase, and always satisfies
//   ticks() + missed_periods() == index of the last tick + 1.
//
// After construction nothing allocates, locks or throws.

#include <cstdint>

#include "core/time/time.h"

namespace rover::runtime {

/// Sleeps until successive deadlines of a fixed-period grid and accounts for
/// periods the caller overran. Owned by one thread.
class PeriodicTimer {
 public:
  /// The timer's source of time; tests inject a fake one.
  class Clock {
   public:
    virtual ~Clock() = default;
    /// Current time on the clock.
    virtual Time Now() = 0;
    /// Returns no earlier than `deadline` (absolute), as soon as possible.
    virtual void SleepUntil(Time deadline) = 0;
  };

  /// CLOCK_MONOTONIC with clock_nanosleep(TIMER_ABSTIME), retried on EINTR.
  /// A process-wide instance that lives forever.
  static Clock& MonotonicClock();

  /// One wake-up of the loop.
  struct Tick {
    int64_t index = 0;            ///< Grid slot served: deadline = first + index * period.
    Time deadline;                ///< The slot's scheduled (absolute) deadline.
    Time woke;                    ///< Clock reading right after the sleep returned.
    uint64_t missed_periods = 0;  ///< Slots skipped since the previous tick.
    /// True if WaitNext() slept until the deadline (woke - deadline is then a
    /// wake-up latency); false for a slot served late, straight after an overrun.
    bool slept = true;
  };

  /// A timer whose first deadline is `first_deadline`. `period` must be
  /// positive (throws std::invalid_argument otherwise, naming the value).
  PeriodicTimer(Duration period, Time first_deadline, Clock& clock = MonotonicClock());

  /// A timer whose first deadline is one period from now.
  explicit PeriodicTimer(Duration period, Clock& clock = MonotonicClock());

  /// Sleeps until the next deadline (or returns at once when it has passed,
  /// skipping slots that passed entirely; see the file comment) and returns
  /// the slot served. Never allocates.
  Tick WaitNext();

  /// Nominal period.
  Duration period() const { return period_; }
  /// Deadline the next WaitNext() will aim for if the loop is on time.
  Time next_deadline() const { return first_deadline_ + period_ * next_index_; }
  /// Deadline of slot 0.
  Time first_deadline() const { return first_deadline_; }
  /// Number of WaitNext() calls completed (slots served).
  uint64_t ticks() const { return ticks_; }
  /// Number of slots skipped because the loop overran them.
  uint64_t missed_periods() const { return missed_periods_; }

 private:
  Duration period_;
  Time first_deadline_;
  Clock* clock_;
  int64_t next_index_ = 0;
  uint64_t ticks_ = 0;
  uint64_t missed_periods_ = 0;
};

}  // namespace rover::runtime

#endif  // ROVER_FIRMWARE_RUNTIME_RT_PERIODIC_TIMER_H_
