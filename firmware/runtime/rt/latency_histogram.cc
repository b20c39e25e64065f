#include "firmware/runtime/rt/latency_histogram.h"

#include <algorithm>
#include <cmath>

namespace rover::runtime {
namespace {

// Rank (1-based) of the sample at quantile q among n samples.
uint64_t RankOf(double q, uint64_t n) {
  const double clamped = std::clamp(q, 0.0, 1.0);
  const auto rank = static_cast<uint64_t>(std::ceil(clamped * static_cast<double>(n)));
  return std::clamp<uint64_t>(rank, 1, n);
}

}  // namespace

LatencyHistogram::LatencyHistogram()
    : min_ns_(std::numeric_limits<int64_t>::max()), max_ns_(std::numeric_limits<int64_t>::min()) {
  for (std::atomic<uint64_t>& bucket : buckets_) bucket.store(0, std::memory_order_relaxed);
}

void LatencyHistogram::Merge(const LatencyHistogram& other) {
  // Totals from other's buckets, read first (acquire): its min, max and sum
  // then cover at least those samples.
  std::array<uint64_t, kBucketCount> added{};
  uint64_t total = 0;
  for (int i = 0; i < kBucketCount; ++i) {
    added[static_cast<std::size_t>(i)] = other.bucket_count(i);
    total += added[static_cast<std::size_t>(i)];
  }
  if (total == 0) return;
  const int64_t other_max = other.max_ns_.load(std::memory_order_relaxed);
  if (other_max > max_ns_.load(std::memory_order_relaxed)) {
    max_ns_.store(other_max, std::memory_order_relaxed);
  }
  const int64_t other_min = other.min_ns_.load(std::memory_order_relaxed);
  if (other_min < min_ns_.load(std::memory_order_relaxed)) {
    min_ns_.store(other_min, std::memory_order_relaxed);
  }
  sum_ns_.store(
      sum_ns_.load(std::memory_order_relaxed) + other.sum_ns_.load(std::memory_order_relaxed),
      std::memory_order_relaxed);
  // This histogram's count must match its own buckets, so it grows by the
  // bucket total (other.count_ can run ahead while other's writer is active).
  Bump(count_, total);
  for (std::size_t i = 0; i < added.size(); ++i) {
    if (added[i] != 0) Bump(buckets_[i], added[i]);
  }
}

void LatencyHistogram::Reset() {
  for (std::atomic<uint64_t>& bucket : buckets_) bucket.store(0, std::memory_order_relaxed);
  count_.store(0, std::memory_order_relaxed);
  sum_ns_.store(0, std::memory_order_relaxed);
  min_ns_.store(std::numeric_limits<int64_t>::max(), std::memory_order_relaxed);
  max_ns_.store(std::numeric_limits<int64_t>::min(), std::memory_order_relaxed);
}

int64_t LatencyHistogram::min_ns() const {
  return count() == 0 ? 0 : min_ns_.load(std::memory_order_relaxed);
}

int64_t LatencyHistogram::max_ns() const {
  return count() == 0 ? 0 : max_ns_.load(std::memory_order_relaxed);
}

int64_t LatencyHistogram::ValueAtQuantile(double q) const {
  // Two passes over the buckets: the total, then the bucket where the
  // cumulative count reaches the rank. Counts only grow while a writer runs,
  // so the second pass always reaches a rank taken from the first.
  uint64_t total = 0;
  for (int i = 0; i < kBucketCount; ++i) total += bucket_count(i);
  if (total == 0) return 0;
  if (q >= 1.0) return max_ns();
  const uint64_t rank = RankOf(q, total);
  uint64_t cumulative = 0;
  for (int i = 0; i < kBucketCount; ++i) {
    cumulative += bucket_count(i);
    if (cumulative >= rank) return BucketLowerNs(i);
  }
  return max_ns();  // Only if Reset() ran between the two passes.
}

LatencySummary LatencyHistogram::Summarize() const {
  LatencySummary s;
  for (int i = 0; i < kBucketCount; ++i) s.count += bucket_count(i);
  if (s.count == 0) return s;
  s.min_ns = min_ns_.load(std::memory_order_relaxed);
  s.max_ns = max_ns_.load(std::memory_order_relaxed);
  s.mean_ns = static_cast<double>(sum_ns_.load(std::memory_order_relaxed)) /
              static_cast<double>(count_.load(std::memory_order_relaxed));
  constexpr std::array<double, 3> kQuantiles = {0.50, 0.99, 0.999};
  std::array<int64_t*, 3> out = {&s.p50_ns, &s.p99_ns, &s.p999_ns};
  std::array<uint64_t, 3> ranks{};
  for (std::size_t k = 0; k < ranks.size(); ++k) {
    ranks[k] = RankOf(kQuantiles[k], s.count);
    *out[k] = s.max_ns;  // Fallback if a concurrent Reset() emptied the buckets.
  }
  std::size_t next = 0;
  uint64_t cumulative = 0;
  for (int i = 0; i < kBucketCount && next < ranks.size(); ++i) {
    cumulative += bucket_count(i);
    while (next < ranks.size() && cumulative >= ranks[next]) {
      *out[next] = BucketLowerNs(i);
      ++next;
    }
  }
  return s;
}

}  // namespace rover::runtime
