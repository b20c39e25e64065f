#ifndef ROVER_FIRMWARE_ROVERD_STEP_LATENCY_H_
#define ROVER_FIRMWARE_ROVERD_STEP_LATENCY_H_

// Wall time of the IMU loop's estimator step, as a fixed histogram (1 us
// buckets up to 10 ms, one overflow bucket): recording never allocates.

#include <array>
#include <cstdint>

#include "core/time/time.h"

namespace rover::roverd {

class StepLatency {
 public:
  struct Percentiles {
    double p50_us = 0.0;
    double p99_us = 0.0;
    double p999_us = 0.0;
    double max_us = 0.0;
    uint64_t count = 0;
  };

  void Record(Duration d) {
    const int64_t us = d.nanoseconds() / 1000;
    const std::size_t bucket =
        us < 0 ? 0
               : (us >= static_cast<int64_t>(kBuckets) ? kBuckets : static_cast<std::size_t>(us));
    ++counts_[bucket];
    if (d.nanoseconds() > max_ns_) max_ns_ = d.nanoseconds();
    ++count_;
  }

  Percentiles Get() const {
    Percentiles p;
    p.count = count_;
    p.max_us = static_cast<double>(max_ns_) / 1000.0;
    p.p50_us = Quantile(0.5);
    p.p99_us = Quantile(0.99);
    p.p999_us = Quantile(0.999);
    return p;
  }

 private:
  static constexpr std::size_t kBuckets = 10000;

  double Quantile(double q) const {
    if (count_ == 0) return 0.0;
    const auto rank = static_cast<uint64_t>(q * static_cast<double>(count_ - 1));
    uint64_t seen = 0;
    for (std::size_t b = 0; b <= kBuckets; ++b) {
      seen += counts_[b];
      if (seen > rank) return static_cast<double>(b) + 0.5;
    }
    return static_cast<double>(kBuckets);
  }

  std::array<uint64_t, kBuckets + 1> counts_{};
  int64_t max_ns_ = 0;
  uint64_t count_ = 0;
};

}  // namespace rover::roverd

#endif  // ROVER_FIRMWARE_ROVERD_STEP_LATENCY_H_
