#include "firmware/runtime/rt/loop_probe.h"

namespace rover::runtime {

LoopProbe::LoopProbe(Duration nominal_period) : nominal_period_(nominal_period) {}

void LoopProbe::OnWake(Time deadline, Time woke, uint64_t missed_periods, bool slept) {
  if (slept) {
    wakeup_latency_.Record((woke - deadline).nanoseconds());
  } else {
    late_ticks_.store(late_ticks_.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
  }
  if (has_previous_) {
    const Duration actual = woke - previous_woke_;
    const Duration scheduled = deadline - previous_deadline_;
    const int64_t jitter_ns = (actual - scheduled).nanoseconds();
    period_jitter_.Record(jitter_ns < 0 ? -jitter_ns : jitter_ns);
  }
  has_previous_ = true;
  previous_deadline_ = deadline;
  previous_woke_ = woke;
  ticks_.store(ticks_.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
  if (missed_periods != 0) {
    missed_periods_.store(missed_periods_.load(std::memory_order_relaxed) + missed_periods,
                          std::memory_order_relaxed);
  }
}

void LoopProbe::Reset() {
  wakeup_latency_.Reset();
  period_jitter_.Reset();
  sample_to_estimate_.Reset();
  ticks_.store(0, std::memory_order_relaxed);
  missed_periods_.store(0, std::memory_order_relaxed);
  late_ticks_.store(0, std::memory_order_relaxed);
  has_previous_ = false;
}

LoopProbeSnapshot LoopProbe::Snapshot() const {
  LoopProbeSnapshot s;
  s.ticks = ticks_.load(std::memory_order_relaxed);
  s.missed_periods = missed_periods_.load(std::memory_order_relaxed);
  s.late_ticks = late_ticks_.load(std::memory_order_relaxed);
  s.wakeup_latency = wakeup_latency_.Summarize();
  s.period_jitter = period_jitter_.Summarize();
  s.sample_to_estimate = sample_to_estimate_.Summarize();
  return s;
}

}  // namespace rover::runtime
