#include "firmware/runtime/health/sensor_monitor.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <stdexcept>
#include <utility>

namespace rover::runtime {
namespace {

// No epoch: what the producer and the histogram slots hold before the first
// sample, so that the first sample of epoch 0 still clears and tags a slot.
constexpr uint64_t kNoEpoch = std::numeric_limits<uint64_t>::max();

std::size_t SlotOf(uint64_t epoch) { return static_cast<std::size_t>(epoch & 1U); }

std::string Number(double value) {
  // std::to_string prints fixed 6 decimals; enough for an error message.
  return std::to_string(value);
}

}  // namespace

std::string_view HealthLevelName(HealthLevel level) {
  switch (level) {
    case HealthLevel::kOk:
      return "ok";
    case HealthLevel::kWarn:
      return "WARN";
    case HealthLevel::kError:
      return "ERROR";
    case HealthLevel::kStale:
      return "STALE";
  }
  return "UNKNOWN";
}

void SensorMonitorOptions::Validate() const {
  if (stale_after <= Duration::Zero()) {
    throw std::invalid_argument(
        "SensorMonitorOptions.stale_after: expected a positive duration, found " +
        stale_after.ToString());
  }
  // Written as a negated range test so that NaN fails too.
  if (!(rate_warn_fraction >= 0.0 && rate_warn_fraction <= 1.0)) {
    throw std::invalid_argument(
        "SensorMonitorOptions.rate_warn_fraction: expected a fraction in [0, 1], found " +
        Number(rate_warn_fraction));
  }
  if (!(gap_factor >= 1.0 && std::isfinite(gap_factor))) {
    throw std::invalid_argument(
        "SensorMonitorOptions.gap_factor: expected a finite number >= 1 (nominal periods), "
        "found " +
        Number(gap_factor));
  }
}

namespace {

// Checks the constructor arguments before any member depends on them (the
// periods are derived from the rate in the member initialisers).
double CheckedRate(const std::string& name, double nominal_rate_hz,
                   const SensorMonitorOptions& options) {
  if (name.empty()) {
    throw std::invalid_argument("SensorMonitor.name: expected a sensor name, found \"\"");
  }
  if (!(nominal_rate_hz > 0.0 && std::isfinite(nominal_rate_hz))) {
    throw std::invalid_argument("SensorMonitor(" + name +
                                ").nominal_rate_hz: expected a positive finite rate, found " +
                                Number(nominal_rate_hz));
  }
  options.Validate();
  return nominal_rate_hz;
}

}  // namespace

SensorMonitor::SensorMonitor(std::string name, double nominal_rate_hz, SensorMonitorOptions options)
    : name_(std::move(name)),
      nominal_rate_hz_(CheckedRate(name_, nominal_rate_hz, options)),
      options_(options),
      nominal_period_(Duration::FromSeconds(1.0 / nominal_rate_hz_)),
      gap_threshold_(Duration::FromSeconds(options.gap_factor / nominal_rate_hz_)),
      producer_epoch_(kNoEpoch) {
  for (std::atomic<uint64_t>& tag : slot_epoch_) tag.store(kNoEpoch, std::memory_order_relaxed);
}

void SensorMonitor::OnSample(Time sample_stamp, Time now) {
  if (has_previous_stamp_) {
    const Duration interval = sample_stamp - previous_stamp_;
    if (interval > gap_threshold_) {
      Bump(gaps_, 1, std::memory_order_relaxed);
      if (interval.nanoseconds() > longest_gap_ns_.load(std::memory_order_relaxed)) {
        longest_gap_ns_.store(interval.nanoseconds(), std::memory_order_relaxed);
      }
    }
  }
  previous_stamp_ = sample_stamp;
  has_previous_stamp_ = true;

  if (options_.measure_latency) {
    // Acquire pairs with the reader's release when it starts an epoch: the
    // reader's reads of the histogram it just closed then happen before any
    // Reset() of that histogram here, two epochs later.
    const uint64_t epoch = epoch_.load(std::memory_order_acquire);
    const std::size_t slot = SlotOf(epoch);
    if (epoch != producer_epoch_) {
      // First sample of a new interval: this slot still holds an interval
      // the reader has already summarised (or nothing). Clear it, then tag
      // it (release) so that a reader seeing the tag sees it cleared.
      latency_[slot].Reset();
      slot_epoch_[slot].store(epoch, std::memory_order_release);
      producer_epoch_ = epoch;
    }
    latency_[slot].Record((now - sample_stamp).nanoseconds());
  }

  if (samples_.load(std::memory_order_relaxed) == 0) {
    first_arrival_ns_.store(now.nanoseconds(), std::memory_order_relaxed);
  }
  last_arrival_ns_.store(now.nanoseconds(), std::memory_order_relaxed);
  // Last, with release: publishes the arrival times stored above.
  Bump(samples_, 1, std::memory_order_release);
}

void SensorMonitor::OnDrop(uint64_t n) { Bump(drops_, n, std::memory_order_relaxed); }

void SensorMonitor::OnError() { Bump(errors_, 1, std::memory_order_relaxed); }

SensorHealth SensorMonitor::Snapshot(Time now) {
  SensorHealth h;
  h.name = name_;
  h.nominal_rate_hz = nominal_rate_hz_;
  h.latency_measured = options_.measure_latency;

  // Close the latency interval first: from here on the producer records into
  // the other histogram, and this one only receives the sample of a producer
  // call already under way. seq_cst (a full fence on x86, once per snapshot)
  // makes the new epoch visible before the histogram is read below; a
  // release store could linger in the store buffer while the producer keeps
  // filling this histogram behind the reader's back.
  const uint64_t epoch = epoch_.load(std::memory_order_relaxed);  // Only this thread writes it.
  epoch_.store(epoch + 1, std::memory_order_seq_cst);
  const std::size_t slot = SlotOf(epoch);
  if (options_.measure_latency && slot_epoch_[slot].load(std::memory_order_acquire) == epoch) {
    h.latency = latency_[slot].Summarize();
  }  // Otherwise no sample arrived in the interval: the slot holds an older one.

  // Acquire on the sample count: the arrival times of those samples are
  // visible below.
  h.samples = samples_.load(std::memory_order_acquire);
  h.drops = drops_.load(std::memory_order_relaxed);
  h.errors = errors_.load(std::memory_order_relaxed);
  h.gaps = gaps_.load(std::memory_order_relaxed);
  h.longest_gap_s =
      Duration::Nanoseconds(longest_gap_ns_.load(std::memory_order_relaxed)).ToSeconds();

  h.has_sample = h.samples > 0;
  Duration since_last_sample = Duration::Max();
  if (h.has_sample) {
    const Time last = Time::FromNanoseconds(last_arrival_ns_.load(std::memory_order_relaxed));
    // A sample recorded after the caller read its clock would give a
    // negative age; it is simply fresh.
    since_last_sample = std::max(Duration::Zero(), now - last);
    h.since_last_sample_s = since_last_sample.ToSeconds();
  } else {
    h.since_last_sample_s = std::numeric_limits<double>::infinity();
  }

  h.interval_s = has_previous_snapshot_ ? (now - previous_snapshot_).ToSeconds() : 0.0;
  h.new_drops = h.drops - previous_drops_;
  h.new_errors = h.errors - previous_errors_;
  h.new_gaps = h.gaps - previous_gaps_;
  has_previous_snapshot_ = true;
  previous_snapshot_ = now;
  previous_drops_ = h.drops;
  previous_errors_ = h.errors;
  previous_gaps_ = h.gaps;

  if (!has_rate_window_ && h.has_sample) {
    // The first window starts at the first arrival; that sample is the
    // start mark, not part of the count.
    has_rate_window_ = true;
    rate_window_start_ = Time::FromNanoseconds(first_arrival_ns_.load(std::memory_order_relaxed));
    rate_window_start_samples_ = 1;
  }
  if (has_rate_window_) {
    const Duration window = now - rate_window_start_;
    h.rate_window_s = window.ToSeconds();
    h.rate_window_samples = h.samples - rate_window_start_samples_;
    h.rate_hz = window > Duration::Zero()
                    ? static_cast<double>(h.rate_window_samples) / h.rate_window_s
                    : 0.0;
    h.rate_judged = window >= nominal_period_ * kMinRateWindowPeriods;
    if (h.rate_judged) {
      h.rate_low = h.rate_hz < options_.rate_warn_fraction * nominal_rate_hz_;
      rate_window_start_ = now;
      rate_window_start_samples_ = h.samples;
    }
  }

  if (!h.has_sample || since_last_sample > options_.stale_after) {
    h.level = HealthLevel::kStale;
  } else if (h.new_errors > 0) {
    h.level = HealthLevel::kError;
  } else if (h.new_drops > 0 || h.new_gaps > 0 || h.rate_low) {
    h.level = HealthLevel::kWarn;
  } else {
    h.level = HealthLevel::kOk;
  }
  return h;
}

}  // namespace rover::runtime
