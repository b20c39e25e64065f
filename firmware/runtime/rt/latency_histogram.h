#ifndef ROVER_FIRMWARE_RUNTIME_RT_LATENCY_HISTOGRAM_H_
#define ROVER_FIRMWARE_RUNTIME_RT_LATENCY_HISTOGRAM_H_

// Fixed-size latency histogram for real-time loops.
//
// Buckets are log-linear over nanoseconds:
//   - [0, 1024 us): 1024 linear buckets of 1 us (the resolution cyclictest
//     reports, so the two are directly comparable);
//   - [1024 us, 2^20 us ~ 1.05 s): 32 buckets per power-of-two octave, each
//     at most 1/32 (3.1 %) of its lower edge wide;
//   - one overflow bucket for everything from 2^20 us up.
// Negative values (a clock read before the deadline it is compared with) are
// counted in the first bucket; min() still reports them exactly.
//
// Concurrency: exactly one thread (the real-time loop) may call Record(),
// Merge() and Reset(). Any number of other threads may read at the same time.
// Every field is an atomic that the single writer updates with a plain load +
// store (no read-modify-write, no lock, no allocation; on x86 these are
// ordinary moves). The writer stores the bucket last with release order and
// readers load buckets with acquire, so a sample seen in a bucket is also
// seen in min, max and count. A summary taken while the writer runs may miss
// the samples recorded during the read; it is never torn.

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <limits>

namespace rover::runtime {

/// Percentiles and extremes of a LatencyHistogram at one moment. Plain value
/// type, cheap to copy into a health report.
struct LatencySummary {
  uint64_t count = 0;
  int64_t min_ns = 0;  ///< Exact smallest recorded value (0 if empty).
  int64_t max_ns = 0;  ///< Exact largest recorded value (0 if empty).
  double mean_ns = 0.0;
  int64_t p50_ns = 0;  ///< Percentiles: lower edge of the bucket holding that rank.
  int64_t p99_ns = 0;
  int64_t p999_ns = 0;
};

/// Lock-free, allocation-free latency histogram: single writer, many readers.
class LatencyHistogram {
 public:
  /// Width of the linear buckets.
  static constexpr int64_t kLinearBucketWidthNs = 1'000;
  /// Number of 1 us buckets, covering [0, 1024 us).
  static constexpr int kLinearBuckets = 1024;
  /// Sub-buckets per power-of-two octave above the linear range.
  static constexpr int kSubBucketsPerOctave = 32;
  /// Octaves 2^10 .. 2^19 us are covered; 2^20 us and above overflow.
  static constexpr int kOctaves = 10;
  /// Index of the overflow bucket.
  static constexpr int kOverflowBucket = kLinearBuckets + kOctaves * kSubBucketsPerOctave;
  /// Total number of buckets, overflow included.
  static constexpr int kBucketCount = kOverflowBucket + 1;
  /// Lower edge of the overflow bucket.
  static constexpr int64_t kOverflowNs = (int64_t{1} << (10 + kOctaves)) * kLinearBucketWidthNs;

  /// Creates an empty histogram. Never allocates (the buckets are inline).
  LatencyHistogram();
  LatencyHistogram(const LatencyHistogram&) = delete;
  LatencyHistogram& operator=(const LatencyHistogram&) = delete;

  /// Adds one sample. Writer thread only; wait-free, never allocates.
  void Record(int64_t value_ns) {
    if (value_ns > max_ns_.load(std::memory_order_relaxed)) {
      max_ns_.store(value_ns, std::memory_order_relaxed);
    }
    if (value_ns < min_ns_.load(std::memory_order_relaxed)) {
      min_ns_.store(value_ns, std::memory_order_relaxed);
    }
    sum_ns_.store(sum_ns_.load(std::memory_order_relaxed) + value_ns, std::memory_order_relaxed);
    count_.store(count_.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
    // Bucket last, with release: a reader that sees the sample in its bucket
    // (acquire) also sees it in min, max, sum and count.
    std::atomic<uint64_t>& bucket = buckets_[static_cast<std::size_t>(BucketIndex(value_ns))];
    bucket.store(bucket.load(std::memory_order_relaxed) + 1, std::memory_order_release);
  }

  /// Adds every sample of `other` to this histogram. Writer thread of this
  /// histogram only; `other` may be written concurrently by its own writer.
  void Merge(const LatencyHistogram& other);

  /// Forgets every sample. Writer thread only.
  void Reset();

  /// Number of samples recorded (any thread).
  uint64_t count() const { return count_.load(std::memory_order_relaxed); }
  /// Exact smallest sample, or 0 if empty (any thread).
  int64_t min_ns() const;
  /// Exact largest sample, or 0 if empty (any thread).
  int64_t max_ns() const;
  /// Number of samples in bucket `bucket` (0 <= bucket < kBucketCount).
  uint64_t bucket_count(int bucket) const {
    return buckets_[static_cast<std::size_t>(bucket)].load(std::memory_order_acquire);
  }

  /// Value at quantile `q` in [0, 1] (0.999 for p99.9): the lower edge of the
  /// bucket holding the sample of rank ceil(q * count), so below 1024 us it
  /// is the value truncated to whole microseconds, as cyclictest reports it.
  /// q = 1 returns the exact maximum; an empty histogram returns 0. Samples
  /// in the overflow bucket report kOverflowNs. Any thread; never allocates.
  int64_t ValueAtQuantile(double q) const;

  /// Count, extremes, mean and p50/p99/p99.9 (any thread; never allocates).
  LatencySummary Summarize() const;

  /// Bucket that holds `value_ns` (negative values go to bucket 0).
  static constexpr int BucketIndex(int64_t value_ns) {
    if (value_ns < kLinearBuckets * kLinearBucketWidthNs) {
      return value_ns < 0 ? 0 : static_cast<int>(value_ns / kLinearBucketWidthNs);
    }
    if (value_ns >= kOverflowNs) return kOverflowBucket;
    const auto us = static_cast<uint64_t>(value_ns / kLinearBucketWidthNs);
    const int octave = 63 - __builtin_clzll(us);  // 10 .. 19
    const int sub = static_cast<int>((us >> (octave - 5)) & (kSubBucketsPerOctave - 1));
    return kLinearBuckets + (octave - 10) * kSubBucketsPerOctave + sub;
  }

  /// Smallest value (ns) that falls in bucket `bucket`.
  static constexpr int64_t BucketLowerNs(int bucket) {
    if (bucket < kLinearBuckets) return bucket * kLinearBucketWidthNs;
    if (bucket >= kOverflowBucket) return kOverflowNs;
    const int octave = 10 + (bucket - kLinearBuckets) / kSubBucketsPerOctave;
    const int sub = (bucket - kLinearBuckets) % kSubBucketsPerOctave;
    const int64_t us = (int64_t{1} << octave) + (int64_t{sub} << (octave - 5));
    return us * kLinearBucketWidthNs;
  }

  /// One past the largest value (ns) of bucket `bucket`; INT64_MAX for overflow.
  static constexpr int64_t BucketUpperNs(int bucket) {
    return bucket >= kOverflowBucket ? std::numeric_limits<int64_t>::max()
                                     : BucketLowerNs(bucket + 1);
  }

 private:
  // Single-writer increment; release so that it publishes earlier stores.
  static void Bump(std::atomic<uint64_t>& counter, uint64_t n) {
    counter.store(counter.load(std::memory_order_relaxed) + n, std::memory_order_release);
  }

  std::array<std::atomic<uint64_t>, kBucketCount> buckets_;
  std::atomic<uint64_t> count_{0};
  std::atomic<int64_t> sum_ns_{0};
  std::atomic<int64_t> min_ns_;
  std::atomic<int64_t> max_ns_;
};

}  // namespace rover::runtime

#endif  // ROVER_FIRMWARE_RUNTIME_RT_LATENCY_HISTOGRAM_H_
