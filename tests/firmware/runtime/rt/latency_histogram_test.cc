#include "firmware/runtime/rt/latency_histogram.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <memory>

#include "tests/support/allocation_counter.h"

namespace rover::runtime {
namespace {

constexpr int64_t kUs = 1'000;
using H = LatencyHistogram;

TEST(LatencyHistogramTest, LinearBucketsAreOneMicrosecondWide) {
  EXPECT_EQ(H::BucketIndex(0), 0);
  EXPECT_EQ(H::BucketIndex(999), 0);
  EXPECT_EQ(H::BucketIndex(1'000), 1);
  EXPECT_EQ(H::BucketIndex(57'400), 57);
  EXPECT_EQ(H::BucketIndex(1023 * kUs + 999), 1023);
  EXPECT_EQ(H::BucketLowerNs(57), 57 * kUs);
  EXPECT_EQ(H::BucketUpperNs(57), 58 * kUs);
}

TEST(LatencyHistogramTest, NegativeValuesGoToTheFirstBucket) {
  EXPECT_EQ(H::BucketIndex(-1), 0);
  EXPECT_EQ(H::BucketIndex(-5'000'000), 0);
}

TEST(LatencyHistogramTest, LogBucketsAboveOneMillisecond) {
  // First octave [1024, 2048) us: 32 buckets of 32 us.
  EXPECT_EQ(H::BucketIndex(1024 * kUs), H::kLinearBuckets);
  EXPECT_EQ(H::BucketIndex(1055 * kUs + 999), H::kLinearBuckets);
  EXPECT_EQ(H::BucketIndex(1056 * kUs), H::kLinearBuckets + 1);
  EXPECT_EQ(H::BucketIndex(2047 * kUs), H::kLinearBuckets + 31);
  // Second octave [2048, 4096) us: 64 us wide.
  EXPECT_EQ(H::BucketIndex(2048 * kUs), H::kLinearBuckets + 32);
  EXPECT_EQ(H::BucketIndex(2111 * kUs), H::kLinearBuckets + 32);
  EXPECT_EQ(H::BucketIndex(2112 * kUs), H::kLinearBuckets + 33);
  EXPECT_EQ(H::BucketLowerNs(H::kLinearBuckets + 33), 2112 * kUs);
}

TEST(LatencyHistogramTest, OverflowBucket) {
  EXPECT_EQ(H::kOverflowNs, (int64_t{1} << 20) * kUs);
  EXPECT_EQ(H::BucketIndex(H::kOverflowNs - 1), H::kOverflowBucket - 1);
  EXPECT_EQ(H::BucketIndex(H::kOverflowNs), H::kOverflowBucket);
  EXPECT_EQ(H::BucketIndex(INT64_MAX), H::kOverflowBucket);
}

TEST(LatencyHistogramTest, EveryBucketHoldsItsOwnEdgesAndIsAtMostOneThirtySecondWide) {
  for (int b = 0; b < H::kOverflowBucket; ++b) {
    const int64_t lower = H::BucketLowerNs(b);
    const int64_t upper = H::BucketUpperNs(b);
    ASSERT_LT(lower, upper) << "bucket " << b;
    EXPECT_EQ(H::BucketIndex(lower), b) << "lower edge of bucket " << b;
    EXPECT_EQ(H::BucketIndex(upper - 1), b) << "upper edge of bucket " << b;
    if (b >= H::kLinearBuckets) {
      EXPECT_LE((upper - lower) * 32, lower) << "bucket " << b;
    } else {
      EXPECT_EQ(upper - lower, kUs);
    }
  }
}

TEST(LatencyHistogramTest, EmptyHistogramReportsZeros) {
  const auto h = std::make_unique<H>();
  const LatencySummary s = h->Summarize();
  EXPECT_EQ(s.count, 0u);
  EXPECT_EQ(s.min_ns, 0);
  EXPECT_EQ(s.max_ns, 0);
  EXPECT_EQ(s.p999_ns, 0);
  EXPECT_EQ(h->ValueAtQuantile(0.5), 0);
}

TEST(LatencyHistogramTest, PercentilesOfOneToThousandMicroseconds) {
  auto h = std::make_unique<H>();
  // 1.5 us, 2.5 us, ..., 1000.5 us: rank k holds k.5 us, reported as k us.
  for (int k = 1000; k >= 1; --k) h->Record(k * kUs + 500);
  const LatencySummary s = h->Summarize();
  EXPECT_EQ(s.count, 1000u);
  EXPECT_EQ(s.min_ns, 1 * kUs + 500);
  EXPECT_EQ(s.max_ns, 1000 * kUs + 500);
  EXPECT_DOUBLE_EQ(s.mean_ns, 500.5 * kUs + 500);
  EXPECT_EQ(s.p50_ns, 500 * kUs);
  EXPECT_EQ(s.p99_ns, 990 * kUs);
  EXPECT_EQ(s.p999_ns, 999 * kUs);
  EXPECT_EQ(h->ValueAtQuantile(0.5), 500 * kUs);
  EXPECT_EQ(h->ValueAtQuantile(0.0), 1 * kUs);
  EXPECT_EQ(h->ValueAtQuantile(1.0), 1000 * kUs + 500);
}

TEST(LatencyHistogramTest, TailInTheCoarseBuckets) {
  auto h = std::make_unique<H>();
  for (int i = 0; i < 998; ++i) h->Record(20 * kUs);
  h->Record(1500 * kUs);          // bucket [1472, 1504) us
  h->Record(H::kOverflowNs * 2);  // overflow
  const LatencySummary s = h->Summarize();
  EXPECT_EQ(s.p50_ns, 20 * kUs);
  EXPECT_EQ(s.p99_ns, 20 * kUs);
  EXPECT_EQ(s.p999_ns, 1472 * kUs);  // rank 999: the 1.5 ms sample, at its bucket's lower edge
  EXPECT_EQ(h->ValueAtQuantile(0.9995), H::kOverflowNs);
  EXPECT_EQ(s.max_ns, H::kOverflowNs * 2);
  EXPECT_EQ(h->bucket_count(H::kOverflowBucket), 1u);
}

TEST(LatencyHistogramTest, MergeAddsCountsAndKeepsExtremes) {
  auto a = std::make_unique<H>();
  auto b = std::make_unique<H>();
  for (int k = 1; k <= 500; ++k) a->Record(k * kUs);
  for (int k = 501; k <= 1000; ++k) b->Record(k * kUs);
  b->Record(-3 * kUs);
  a->Merge(*b);
  const LatencySummary s = a->Summarize();
  EXPECT_EQ(s.count, 1001u);
  EXPECT_EQ(s.min_ns, -3 * kUs);
  EXPECT_EQ(s.max_ns, 1000 * kUs);
  EXPECT_EQ(a->bucket_count(0), 1u);
  EXPECT_EQ(a->bucket_count(700), 1u);
  EXPECT_EQ(s.p50_ns, 500 * kUs);  // rank 501 of {-3, 1..1000}
  // Merging an empty histogram changes nothing.
  auto empty = std::make_unique<H>();
  a->Merge(*empty);
  EXPECT_EQ(a->count(), 1001u);
  EXPECT_EQ(a->min_ns(), -3 * kUs);
}

TEST(LatencyHistogramTest, ResetForgetsEverything) {
  auto h = std::make_unique<H>();
  h->Record(5 * kUs);
  h->Reset();
  EXPECT_EQ(h->count(), 0u);
  EXPECT_EQ(h->bucket_count(5), 0u);
  h->Record(7 * kUs);
  EXPECT_EQ(h->min_ns(), 7 * kUs);
  EXPECT_EQ(h->max_ns(), 7 * kUs);
}

TEST(LatencyHistogramTest, RecordAndSummarizeNeverAllocate) {
  auto h = std::make_unique<H>();
  auto other = std::make_unique<H>();
  other->Record(3 * kUs);
  testing::ScopedAllocationCheck check;
  for (int64_t v = -10'000; v < 3'000'000'000; v += 7'777'777) h->Record(v);
  h->Merge(*other);
  const LatencySummary s = h->Summarize();
  EXPECT_EQ(check.allocations(), 0u);
  EXPECT_GT(s.count, 0u);
}

}  // namespace
}  // namespace rover::runtime
