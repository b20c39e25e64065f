#ifndef ROVER_DRIVERS_CAMERA_DEVICE_CLOCK_FIT_H_
#define ROVER_DRIVERS_CAMERA_DEVICE_CLOCK_FIT_H_

// Maps a device clock (a GigE Vision camera's timestamp counter, in ns) onto
// the host's CLOCK_MONOTONIC from (device time, host receive time) pairs.
//
// A pair's host time is when the host saw the event, which is always LATER
// than the true host time of the device timestamp: transport, interrupt and
// scheduling latency only ever add. So the fit is the lower envelope of the
// pairs, not a least-squares line through them: of all lines host = a +
// b * device lying under every pair, it takes the one closest to them in the
// mean (the linear-programming clock-skew estimator). That line is the lower
// convex hull edge spanning the mean device time; late outliers, however
// large, never touch it. What the fit cannot see is the minimum latency
// itself: the mapped time is the earliest possible receive time, and a
// caller subtracts a known constant latency if it has one.
//
// A pair far BELOW the envelope cannot come from latency: the device clock
// jumped (counter reset, device reboot) and the fit restarts from that pair.
// So does a run of pairs far above it (the offset changed for good, e.g. the
// host receive clock was stepped). The drift estimate survives a restart
// until the window is full again: the oscillator did not change.
//
// Pairs closer together than `pair_spacing` share one slot of the window,
// which keeps the one with the least latency: the window then spans
// window_size * pair_spacing of device time whatever the frame rate, and
// each slot holds the minimum of several frames.
//
// Everything is sized at construction; Add() and ToHost() never allocate.

#include <cmath>
#include <cstdint>
#include <vector>

#include "core/time/time.h"

namespace rover::drivers {

/// Parameters of DeviceClockFit. Validate() throws std::invalid_argument.
struct DeviceClockFitOptions {
  /// Slots in the sliding window (the newest `window_size`; with the
  /// default spacing 25.6 s of device time). The drift error falls roughly
  /// with the square of the span: at 30 Hz with 0.4 ms mean excess latency
  /// (exponential), 4 s give up to ~45 ppm, 25 s under 1 ppm.
  int window_size = 512;
  /// Pairs less than this apart on the device clock share a slot (the
  /// least late one is kept). 0 gives every pair its own slot.
  Duration pair_spacing = Duration::Milliseconds(50);
  /// A pair this far below the fit, or `reset_run_length` consecutive pairs
  /// this far above it, restart the fit. Must exceed the worst latency
  /// jitter that is not an outlier.
  Duration reset_threshold = Duration::Milliseconds(20);
  /// Consecutive far-above pairs that mean the offset changed for good.
  int reset_run_length = 8;
  /// Drift estimates are clamped to +-max_drift_ppm (two crystals of
  /// +-100 ppm differ by at most 200 ppm).
  double max_drift_ppm = 200.0;
  /// Below this span of device time in the window the drift is not
  /// estimated; the last estimate (0 at first) is kept and only the offset
  /// is fitted (so during the first 10 s a 50 ppm drift costs up to 0.5 ms).
  /// Short spans estimate it badly: over 3 s of a camera with millisecond
  /// latency jitter the slope error reaches hundreds of ppm. After a reset,
  /// an estimate made from a full window is kept until the window is full
  /// again: a partial window estimates it worse.
  Duration min_span_for_drift = Duration::Seconds(10);

  /// Throws std::invalid_argument naming the first bad field, with the
  /// expected range and the value found.
  void Validate() const;
};

/// Robust online fit host = a + b * device over a sliding window.
class DeviceClockFit {
 public:
  /// What Add() did with a pair.
  enum class AddResult {
    kAccepted,  ///< within reset_threshold of the fit (or the fit is empty)
    kOutlier,   ///< more than reset_threshold late; kept, but cannot move the envelope
    kReset,     ///< started a new fit (device time went back, far-early pair, or a late run)
    kIgnored,   ///< same device time as the previous pair; dropped
  };

  /// Allocates the window. Throws std::invalid_argument for bad options.
  explicit DeviceClockFit(const DeviceClockFitOptions& options = {});

  /// Adds one pair: `device_ns` on the device clock (strictly increasing
  /// between resets) and the host CLOCK_MONOTONIC time it was received.
  /// O(window_size); never allocates.
  AddResult Add(int64_t device_ns, Time host_receive);

  /// Host time of `device_ns` on the fitted envelope. Extrapolates outside
  /// the window. Requires valid().
  Time ToHost(int64_t device_ns) const;

  /// True once the window holds at least one pair.
  bool valid() const { return count_ > 0; }
  /// Slots currently in the window.
  int size() const { return count_; }
  /// host - device at the newest device time in the window (the fitted
  /// offset a + (b - 1) * device).
  Duration offset() const;
  /// Rate of the host clock against the device clock, (b - 1) * 1e6: a
  /// device running 50 ppm slow gives +50.
  double drift_ppm() const { return drift_ * 1e6; }
  /// How far the last pair lay above the envelope, and the running mean of
  /// that over the last ~64 pairs: the receive latency in excess of the
  /// minimum.
  Duration last_residual() const { return Duration::Nanoseconds(last_residual_ns_); }
  Duration mean_residual() const { return Duration::Nanoseconds(std::llround(mean_residual_ns_)); }
  /// Restarts of the fit since construction.
  uint64_t resets() const { return resets_; }
  /// Pairs reported kOutlier since construction.
  uint64_t outliers() const { return outliers_; }

  /// Empties the window (keeps the drift estimate and the counters).
  void Clear();

 private:
  struct Pair {
    int64_t device_ns = 0;
    int64_t host_ns = 0;
  };

  const Pair& At(int i) const;  // i-th oldest pair in the window
  void Refit();

  DeviceClockFitOptions options_;
  std::vector<Pair> ring_;  // capacity window_size, never resized after construction
  std::vector<int> hull_;   // lower-hull scratch, same capacity
  int head_ = 0;            // index of the oldest pair
  int count_ = 0;
  int late_run_ = 0;
  // Fit: host = ref_host + x + alpha + drift * x with x = device - ref_device.
  int64_t ref_device_ns_ = 0;
  int64_t ref_host_ns_ = 0;
  double alpha_ns_ = 0.0;
  double drift_ = 0.0;
  bool drift_from_full_window_ = false;
  int64_t last_device_ns_ = 0;  // of the last pair added (a slot keeps its least late one)
  int64_t slot_start_ns_ = 0;   // device time of the newest slot's first pair
  int64_t last_residual_ns_ = 0;
  double mean_residual_ns_ = 0.0;
  uint64_t resets_ = 0;
  uint64_t outliers_ = 0;
};

}  // namespace rover::drivers

#endif  // ROVER_DRIVERS_CAMERA_DEVICE_CLOCK_FIT_H_
