#ifndef ROVER_FIRMWARE_RUNTIME_HEALTH_SENSOR_MONITOR_H_
#define ROVER_FIRMWARE_RUNTIME_HEALTH_SENSOR_MONITOR_H_

// Per-sensor statistics: how many samples arrived, how regularly, how late,
// and whether the driver dropped or failed any; judged as OK / WARN / ERROR /
// STALE by the health thread.
//
// Two threads, one role each:
//   - the producer (the sensor's driver thread, possibly real-time) calls
//     OnSample(), OnDrop() and OnError(). These are wait-free and never
//     allocate or lock: every shared field is an atomic that only the producer
//     writes, with a plain load + store (no read-modify-write);
//   - the reader (the health thread) calls Snapshot() periodically. It may
//     allocate (it copies the name), it never blocks the producer.
//
// Clocks: `now` (OnSample's and Snapshot's) is always CLOCK_MONOTONIC
// (rover::Time::Now()). A sample's own stamp may come from another clock
// (e.g. a camera's hardware clock): gaps only compare stamps with each other,
// and latency (now - stamp) can be switched off for such sensors
// (SensorMonitorOptions::measure_latency).
//
// Interval statistics (rate, new drops / gaps / errors, latency percentiles)
// cover the time since the previous Snapshot(). The latency histograms are
// double-buffered: Snapshot() starts a new interval by bumping an epoch
// counter, and the producer switches to (and clears) the other histogram at
// its next sample. A sample the producer records while Snapshot() runs may
// be missing from the interval's latency percentiles; counters (samples,
// drops, errors, gaps) never lose anything, and nothing is ever torn.
//
// The two histograms are held inline (about 22 KiB): create the monitor
// before the threads start (as a member or on the heap), not on a
// prefaulted real-time stack.

#include <atomic>
#include <cstdint>
#include <string>
#include <string_view>

#include "core/time/time.h"
#include "firmware/runtime/rt/latency_histogram.h"

namespace rover::runtime {

/// Health of one component, worst last. The values are those of
/// diagnostic_msgs/DiagnosticStatus.level, so a level converts to the
/// message's byte with a static_cast.
enum class HealthLevel : uint8_t {
  kOk = 0,
  kWarn = 1,
  kError = 2,
  kStale = 3,
};

/// "ok", "WARN", "ERROR" or "STALE": problems in capitals, so they stand out
/// in a status line full of healthy sensors.
std::string_view HealthLevelName(HealthLevel level);

/// How a SensorMonitor judges its sensor.
struct SensorMonitorOptions {
  /// STALE when no sample arrived for longer than this (or none ever did).
  Duration stale_after = Duration::Seconds(1);
  /// WARN when the interval's rate is below this fraction of the nominal
  /// rate. 0 disables the rate check.
  double rate_warn_fraction = 0.9;
  /// A gap is an interval between consecutive sample stamps longer than
  /// gap_factor nominal periods: 1.5 catches one missing sample while
  /// tolerating the jitter of a healthy driver.
  double gap_factor = 1.5;
  /// Record now - stamp as latency. False for sensors whose stamps are on
  /// another clock than CLOCK_MONOTONIC (the difference would be
  /// meaningless); the latency fields of SensorHealth then stay zero.
  bool measure_latency = true;

  /// Throws std::invalid_argument "SensorMonitorOptions.<field>: expected
  /// ..., found ..." if stale_after is not positive, rate_warn_fraction is
  /// not in [0, 1] or gap_factor is not a finite number >= 1.
  void Validate() const;
};

/// One sensor's health at one Snapshot(). Plain value type.
struct SensorHealth {
  std::string name;
  HealthLevel level = HealthLevel::kStale;
  double nominal_rate_hz = 0.0;

  // Totals since the monitor was created.
  uint64_t samples = 0;
  uint64_t drops = 0;          ///< Samples the driver reported lost (OnDrop).
  uint64_t errors = 0;         ///< Driver errors (OnError).
  uint64_t gaps = 0;           ///< Stamp intervals longer than gap_factor nominal periods.
  double longest_gap_s = 0.0;  ///< Longest stamp interval that counted as a gap.

  // The interval since the previous Snapshot() (since creation for the
  // first one, whose interval_s is 0: the monitor has no clock of its own).
  double interval_s = 0.0;
  uint64_t new_drops = 0;
  uint64_t new_errors = 0;
  uint64_t new_gaps = 0;

  // Rate: samples counted over the rate window, which spans one or more
  // snapshot intervals (see SensorMonitor::Snapshot).
  double rate_window_s = 0.0;
  uint64_t rate_window_samples = 0;
  double rate_hz = 0.0;      ///< rate_window_samples / rate_window_s (0 if the window is empty).
  bool rate_judged = false;  ///< The window was long enough to judge the rate (and now restarts).
  bool rate_low = false;     ///< rate_judged and rate_hz < rate_warn_fraction * nominal.

  bool has_sample = false;  ///< At least one sample arrived since creation.
  /// Snapshot time - arrival of the latest sample; +infinity if none arrived.
  double since_last_sample_s = 0.0;

  bool latency_measured = false;  ///< SensorMonitorOptions::measure_latency.
  /// Latency (arrival - stamp) of the interval's samples: count, p50, p99,
  /// max (and min, mean, p99.9). All zero if no sample was recorded.
  LatencySummary latency;
};

/// Lock-free, allocation-free statistics of one sensor stream: one producer
/// thread, one reader thread (see the file comment).
class SensorMonitor {
 public:
  /// A monitor for sensor `name` delivering `nominal_rate_hz` samples per
  /// second. Throws std::invalid_argument if the name is empty, the rate is
  /// not a positive finite number or `options` fail Validate().
  SensorMonitor(std::string name, double nominal_rate_hz, SensorMonitorOptions options = {});
  SensorMonitor(const SensorMonitor&) = delete;
  SensorMonitor& operator=(const SensorMonitor&) = delete;

  /// Producer: one sample stamped `sample_stamp` arrived at `now`
  /// (CLOCK_MONOTONIC). Counts it, checks the stamp interval since the
  /// previous sample for a gap and, if latency is measured, records
  /// now - sample_stamp. Wait-free and allocation-free; at the first sample
  /// of each snapshot interval it also clears that interval's histogram
  /// (about 1400 stores, once per interval).
  void OnSample(Time sample_stamp, Time now);

  /// Producer: the driver lost `n` samples (overrun FIFO, full ring, ...).
  /// Wait-free.
  void OnDrop(uint64_t n = 1);

  /// Producer: the driver hit an error (bad checksum, timeout, bus error).
  /// Wait-free.
  void OnError();

  /// Reader: the sensor's health at `now` (CLOCK_MONOTONIC). New drops,
  /// gaps, errors and the latency percentiles cover the interval since the
  /// previous call (since creation for the first), which this call ends.
  ///
  /// The rate is counted over a window of whole snapshot intervals that
  /// lasts until it spans at least kMinRateWindowPeriods nominal periods;
  /// only then is it judged (rate_judged) and a new window started. Why: a
  /// window that holds k periods counts k +- 1 samples depending on phase,
  /// so a 10 Hz camera seen over 1 s would read 9 Hz now and then and warn
  /// for nothing. The first window starts at the first sample's arrival;
  /// that sample marks the start and is not counted, so the rate of a
  /// steady stream comes out exact.
  ///
  /// Level, first match wins: STALE if no sample arrived for longer than
  /// stale_after (or none ever did); ERROR if new errors; WARN if new drops,
  /// new gaps or a judged low rate; otherwise OK. Reader thread only (it
  /// keeps the previous snapshot's counters); never blocks the producer.
  SensorHealth Snapshot(Time now);

  /// Nominal periods a rate window must span before the rate is judged: 20
  /// keeps the +-1 sample counting error at 5 %, half the default 10 %
  /// warning margin.
  static constexpr int64_t kMinRateWindowPeriods = 20;

  /// Name given at construction.
  const std::string& name() const { return name_; }
  /// Nominal rate given at construction.
  double nominal_rate_hz() const { return nominal_rate_hz_; }
  /// Options given at construction.
  const SensorMonitorOptions& options() const { return options_; }

 private:
  // Single-writer increment (the producer is the only writer): a plain
  // load + store instead of a locked read-modify-write.
  static void Bump(std::atomic<uint64_t>& counter, uint64_t n, std::memory_order order) {
    counter.store(counter.load(std::memory_order_relaxed) + n, order);
  }

  // Constant after construction.
  const std::string name_;
  const double nominal_rate_hz_;
  const SensorMonitorOptions options_;
  const Duration nominal_period_;
  const Duration gap_threshold_;

  // Written by the producer, read by the reader. `samples_` is stored last
  // with release, so a reader that sees a sample count (acquire) also sees
  // the arrival times of those samples.
  std::atomic<uint64_t> samples_{0};
  std::atomic<uint64_t> drops_{0};
  std::atomic<uint64_t> errors_{0};
  std::atomic<uint64_t> gaps_{0};
  std::atomic<int64_t> longest_gap_ns_{0};
  std::atomic<int64_t> first_arrival_ns_{0};
  std::atomic<int64_t> last_arrival_ns_{0};

  // Interval latency, double-buffered. Written by the reader only: epoch_
  // (the interval being recorded). Written by the producer only: the
  // histograms and slot_epoch_, the epoch each histogram currently holds,
  // stored (release) after the histogram was cleared for it.
  std::atomic<uint64_t> epoch_{0};
  LatencyHistogram latency_[2];
  std::atomic<uint64_t> slot_epoch_[2];

  // Producer-only state (never read by the reader).
  uint64_t producer_epoch_;
  Time previous_stamp_;
  bool has_previous_stamp_ = false;

  // Reader-only state: where the current rate window started, and the
  // totals of the previous snapshot.
  bool has_rate_window_ = false;
  Time rate_window_start_;
  uint64_t rate_window_start_samples_ = 0;
  bool has_previous_snapshot_ = false;
  Time previous_snapshot_;
  uint64_t previous_drops_ = 0;
  uint64_t previous_errors_ = 0;
  uint64_t previous_gaps_ = 0;
};

}  // namespace rover::runtime

#endif  // ROVER_FIRMWARE_RUNTIME_HEALTH_SENSOR_MONITOR_H_
