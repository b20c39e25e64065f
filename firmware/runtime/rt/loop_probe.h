#ifndef ROVER_FIRMWARE_RUNTIME_RT_LOOP_PROBE_H_
#define ROVER_FIRMWARE_RUNTIME_RT_LOOP_PROBE_H_

// The built-in latency probe of a periodic real-time loop (the IMU loop).
//
// Per iteration the loop reports its wake-up and, when it publishes, the
// estimate; the probe keeps three histograms:
//   - wake-up latency: actual wake-up - scheduled deadline, for wake-ups
//     from a sleep (what cyclictest measures). A slot served late straight
//     after an overrun, without sleeping, has no wake-up: it is counted in
//     late_ticks instead (its lateness still shows in sample to estimate);
//   - period jitter: |actual period - scheduled period|, where the actual
//     period is the time between two consecutive wake-ups and the scheduled
//     one the time between their deadlines (one nominal period, or several
//     when the timer skipped overrun slots);
//   - sample to estimate: publication time of an estimate - time of the
//     sensor sample it is based on.
//
// Writer side (OnWake, OnEstimatePublished, Reset): the loop's thread only;
// wait-free, no allocation, no lock. Snapshot() and the histogram accessors
// may be called from any thread at any time (see LatencyHistogram).
//
// The three histograms are held inline (about 32 KiB): create the probe
// before the loop starts (as a member or on the heap), not on a prefaulted
// real-time stack.

#include <atomic>
#include <cstdint>

#include "core/time/time.h"
#include "firmware/runtime/rt/latency_histogram.h"
#include "firmware/runtime/rt/periodic_timer.h"

namespace rover::runtime {

/// Loop statistics at one moment, for health reporting.
struct LoopProbeSnapshot {
  uint64_t ticks = 0;           ///< Wake-ups recorded.
  uint64_t missed_periods = 0;  ///< Periods skipped by overruns.
  uint64_t late_ticks = 0;      ///< Slots served late after an overrun, without sleeping.
  LatencySummary wakeup_latency;
  LatencySummary period_jitter;
  LatencySummary sample_to_estimate;
};

/// Wake-up latency, period jitter and sample-to-estimate histograms of one
/// periodic loop.
class LoopProbe {
 public:
  /// A probe for a loop with nominal period `nominal_period` (informational:
  /// jitter is measured against the deadlines actually scheduled).
  explicit LoopProbe(Duration nominal_period);
  LoopProbe(const LoopProbe&) = delete;
  LoopProbe& operator=(const LoopProbe&) = delete;

  /// Records one iteration of the loop: `deadline` is the slot's scheduled
  /// time, `woke` the clock reading when the iteration started,
  /// `missed_periods` the slots skipped since the previous iteration and
  /// `slept` whether the loop slept until `deadline` (false: a late slot
  /// served straight after an overrun, which has no wake-up latency).
  void OnWake(Time deadline, Time woke, uint64_t missed_periods = 0, bool slept = true);

  /// Records one iteration from a PeriodicTimer tick.
  void OnWake(const PeriodicTimer::Tick& tick) {
    OnWake(tick.deadline, tick.woke, tick.missed_periods, tick.slept);
  }

  /// Records that an estimate built from the sensor sample taken at
  /// `sample_time` was published at `published`.
  void OnEstimatePublished(Time sample_time, Time published) {
    sample_to_estimate_.Record((published - sample_time).nanoseconds());
  }

  /// Forgets everything (e.g. after start-up transients). Writer thread only.
  void Reset();

  /// Counters and the summaries of all three histograms (any thread).
  LoopProbeSnapshot Snapshot() const;

  /// Nominal loop period given at construction.
  Duration nominal_period() const { return nominal_period_; }
  /// Wake-up latency histogram (ns), wake-ups from a sleep only.
  const LatencyHistogram& wakeup_latency() const { return wakeup_latency_; }
  /// Period jitter histogram (absolute deviation, ns).
  const LatencyHistogram& period_jitter() const { return period_jitter_; }
  /// Sample-to-estimate latency histogram (ns).
  const LatencyHistogram& sample_to_estimate() const { return sample_to_estimate_; }

 private:
  Duration nominal_period_;
  LatencyHistogram wakeup_latency_;
  LatencyHistogram period_jitter_;
  LatencyHistogram sample_to_estimate_;
  std::atomic<uint64_t> ticks_{0};
  std::atomic<uint64_t> missed_periods_{0};
  std::atomic<uint64_t> late_ticks_{0};
  // Writer-thread state: the previous wake-up, for the period.
  bool has_previous_ = false;
  Time previous_deadline_;
  Time previous_woke_;
};

}  // namespace rover::runtime

#endif  // ROVER_FIRMWARE_RUNTIME_RT_LOOP_PROBE_H_
