#include "drivers/camera/device_clock_fit.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace rover::drivers {
namespace {

[[noreturn]] void Invalid(const std::string& field, const std::string& expected,
                          const std::string& found) {
  throw std::invalid_argument("DeviceClockFitOptions." + field + ": expected " + expected +
                              ", found " + found);
}

}  // namespace

void DeviceClockFitOptions::Validate() const {
  // The hull needs two pairs; beyond 1 << 16 the O(n) refit per frame costs
  // more than it could ever gain.
  if (window_size < 2 || window_size > (1 << 16)) {
    Invalid("window_size", "2..65536", std::to_string(window_size));
  }
  if (reset_threshold <= Duration::Zero()) {
    Invalid("reset_threshold", "> 0", reset_threshold.ToString());
  }
  if (reset_run_length < 1) Invalid("reset_run_length", ">= 1", std::to_string(reset_run_length));
  if (!(max_drift_ppm >= 0.0 && max_drift_ppm <= 1e5)) {
    Invalid("max_drift_ppm", "0..100000", std::to_string(max_drift_ppm));
  }
  if (pair_spacing < Duration::Zero() || pair_spacing > Duration::Seconds(10)) {
    Invalid("pair_spacing", "0..10 s", pair_spacing.ToString());
  }
  if (min_span_for_drift < Duration::Zero()) {
    Invalid("min_span_for_drift", ">= 0", min_span_for_drift.ToString());
  }
}

DeviceClockFit::DeviceClockFit(const DeviceClockFitOptions& options) : options_(options) {
  options_.Validate();
  ring_.resize(static_cast<std::size_t>(options_.window_size));
  hull_.resize(static_cast<std::size_t>(options_.window_size));
}

const DeviceClockFit::Pair& DeviceClockFit::At(int i) const {
  int index = head_ + i;
  if (index >= options_.window_size) index -= options_.window_size;
  return ring_[static_cast<std::size_t>(index)];
}

void DeviceClockFit::Clear() {
  head_ = 0;
  count_ = 0;
  late_run_ = 0;
  alpha_ns_ = 0.0;
}

DeviceClockFit::AddResult DeviceClockFit::Add(int64_t device_ns, Time host_receive) {
  const int64_t host_ns = host_receive.nanoseconds();
  AddResult result = AddResult::kAccepted;
  int64_t residual_ns = 0;
  if (count_ > 0) {
    if (device_ns == last_device_ns_) return AddResult::kIgnored;
    residual_ns = host_ns - ToHost(device_ns).nanoseconds();
    const int64_t threshold_ns = options_.reset_threshold.nanoseconds();
    if (device_ns < last_device_ns_ || residual_ns < -threshold_ns) {
      // The device clock went back, or the pair precedes what its own
      // timestamp allows: the old relation no longer holds.
      result = AddResult::kReset;
    } else if (residual_ns > threshold_ns) {
      ++outliers_;
      result = ++late_run_ >= options_.reset_run_length ? AddResult::kReset : AddResult::kOutlier;
    } else {
      late_run_ = 0;
    }
    if (result == AddResult::kReset) {
      ++resets_;
      Clear();
    }
  }
  last_device_ns_ = device_ns;
  const bool fresh = count_ == 0;
  if (count_ > 0 && device_ns - slot_start_ns_ < options_.pair_spacing.nanoseconds()) {
    // Same slot as the newest pair: keep whichever arrived less late (both
    // measured against the current fit, so drift within the slot cancels).
    int newest_index = head_ + count_ - 1;
    if (newest_index >= options_.window_size) newest_index -= options_.window_size;
    Pair& newest = ring_[static_cast<std::size_t>(newest_index)];
    if (residual_ns < newest.host_ns - ToHost(newest.device_ns).nanoseconds()) {
      newest = Pair{device_ns, host_ns};
      Refit();
    }
  } else {
    slot_start_ns_ = device_ns;
    // Append, overwriting the oldest slot once the window is full.
    if (count_ < options_.window_size) {
      int index = head_ + count_;
      if (index >= options_.window_size) index -= options_.window_size;
      ring_[static_cast<std::size_t>(index)] = Pair{device_ns, host_ns};
      ++count_;
    } else {
      ring_[static_cast<std::size_t>(head_)] = Pair{device_ns, host_ns};
      head_ = head_ + 1 == options_.window_size ? 0 : head_ + 1;
    }
    Refit();
  }
  last_residual_ns_ = host_ns - ToHost(device_ns).nanoseconds();
  // Running mean over ~64 pairs; restarted with the fit.
  constexpr double kGain = 1.0 / 64.0;
  const double residual = static_cast<double>(last_residual_ns_);
  mean_residual_ns_ = fresh ? residual : mean_residual_ns_ + kGain * (residual - mean_residual_ns_);
  return result;
}

void DeviceClockFit::Refit() {
  // Work relative to the newest pair, in "excess" coordinates
  // x = device - ref_device, y = (host - ref_host) - x: y is only offset
  // change and latency, small numbers a double holds to well below 1 ns,
  // whereas raw device stamps (~1e18 ns) would lose 8 bits.
  const Pair& newest = At(count_ - 1);
  ref_device_ns_ = newest.device_ns;
  ref_host_ns_ = newest.host_ns;
  const auto x_of = [&](const Pair& p) {
    return static_cast<double>(p.device_ns - ref_device_ns_);
  };
  const auto y_of = [&](const Pair& p) {
    return static_cast<double>((p.host_ns - ref_host_ns_) - (p.device_ns - ref_device_ns_));
  };

  const double span_ns = -x_of(At(0));
  const bool full = count_ == options_.window_size;
  if (count_ >= 2 && span_ns >= static_cast<double>(options_.min_span_for_drift.nanoseconds()) &&
      (full || !drift_from_full_window_)) {
    // Lower convex hull (Andrew's monotone chain; the window is already
    // sorted by device time).
    int n_hull = 0;
    double sum_x = 0.0;
    for (int i = 0; i < count_; ++i) {
      const Pair& p = At(i);
      const double px = x_of(p);
      const double py = y_of(p);
      sum_x += px;
      while (n_hull >= 2) {
        const Pair& o = At(hull_[static_cast<std::size_t>(n_hull - 2)]);
        const Pair& a = At(hull_[static_cast<std::size_t>(n_hull - 1)]);
        const double cross =
            (x_of(a) - x_of(o)) * (py - y_of(o)) - (y_of(a) - y_of(o)) * (px - x_of(o));
        if (cross > 0.0) break;  // counter-clockwise turn: a stays on the lower hull
        --n_hull;
      }
      hull_[static_cast<std::size_t>(n_hull++)] = i;
    }
    // The line minimising the summed distance above it, subject to lying
    // under every pair, is the hull edge over the mean device time.
    const double mean_x = sum_x / static_cast<double>(count_);
    for (int k = 0; k + 1 < n_hull; ++k) {
      const Pair& a = At(hull_[static_cast<std::size_t>(k)]);
      const Pair& b = At(hull_[static_cast<std::size_t>(k + 1)]);
      if (x_of(b) >= mean_x || k + 2 == n_hull) {
        drift_ = (y_of(b) - y_of(a)) / (x_of(b) - x_of(a));
        break;
      }
    }
    const double max_drift = options_.max_drift_ppm * 1e-6;
    drift_ = std::clamp(drift_, -max_drift, max_drift);
    drift_from_full_window_ = drift_from_full_window_ || full;
  }
  // Offset of the supporting line with that slope: the lowest pair.
  double alpha = std::numeric_limits<double>::infinity();
  for (int i = 0; i < count_; ++i) {
    const Pair& p = At(i);
    alpha = std::min(alpha, y_of(p) - drift_ * x_of(p));
  }
  alpha_ns_ = alpha;
}

Time DeviceClockFit::ToHost(int64_t device_ns) const {
  const int64_t x = device_ns - ref_device_ns_;
  return Time::FromNanoseconds(ref_host_ns_ + x +
                               std::llround(alpha_ns_ + drift_ * static_cast<double>(x)));
}

Duration DeviceClockFit::offset() const {
  return Duration::Nanoseconds(ref_host_ns_ - ref_device_ns_ + std::llround(alpha_ns_));
}

}  // namespace rover::drivers
