// A real-time writer and a health reader on one histogram and one probe at
// the same time (run under TSan as well).

#include <gtest/gtest.h>

#include <atomic>
#include <cstdint>
#include <memory>
#include <thread>

#include "firmware/runtime/rt/latency_histogram.h"
#include "firmware/runtime/rt/loop_probe.h"

namespace rover::runtime {
namespace {

TEST(LatencyHistogramConcurrencyTest, ReaderSeesConsistentMonotoneCountsWhileWriterRecords) {
  auto h = std::make_unique<LatencyHistogram>();
  constexpr int kSamples = 200'000;
  std::atomic<bool> done{false};
  std::thread writer([&] {
    for (int i = 0; i < kSamples; ++i) h->Record(int64_t{1'000} + (i % 3'000) * 997);
    done = true;
  });
  uint64_t last_count = 0;
  int reads = 0;
  while (!done.load() || reads < 10) {
    const LatencySummary s = h->Summarize();
    ASSERT_GE(s.count, last_count);
    if (s.count > 0) {
      ASSERT_LE(s.min_ns, s.p50_ns + 1'000);  // min is exact, p50 a bucket edge
      ASSERT_LE(s.p50_ns, s.p99_ns);
      ASSERT_LE(s.p99_ns, s.p999_ns);
      ASSERT_LE(s.p999_ns, s.max_ns);
    }
    last_count = s.count;
    ++reads;
  }
  writer.join();
  EXPECT_EQ(h->count(), static_cast<uint64_t>(kSamples));
  uint64_t total = 0;
  for (int b = 0; b < LatencyHistogram::kBucketCount; ++b) total += h->bucket_count(b);
  EXPECT_EQ(total, static_cast<uint64_t>(kSamples));
}

TEST(LatencyHistogramConcurrencyTest, ProbeSnapshotWhileTheLoopRuns) {
  auto probe = std::make_unique<LoopProbe>(Duration::Milliseconds(1));
  std::atomic<bool> done{false};
  std::thread loop([&] {
    const Time start = Time::FromNanoseconds(1'000'000'000);
    for (int64_t k = 0; k < 50'000; ++k) {
      const Time deadline = start + Duration::Milliseconds(1) * k;
      probe->OnWake(deadline, deadline + Duration::Microseconds(5 + k % 40));
      probe->OnEstimatePublished(deadline, deadline + Duration::Microseconds(30));
    }
    done = true;
  });
  uint64_t last_ticks = 0;
  while (!done.load()) {
    const LoopProbeSnapshot s = probe->Snapshot();
    ASSERT_GE(s.ticks, last_ticks);
    last_ticks = s.ticks;
  }
  loop.join();
  const LoopProbeSnapshot s = probe->Snapshot();
  EXPECT_EQ(s.ticks, 50'000u);
  EXPECT_EQ(s.wakeup_latency.count, 50'000u);
  EXPECT_EQ(s.period_jitter.count, 49'999u);
  EXPECT_EQ(s.sample_to_estimate.p999_ns, 30'000);
}

}  // namespace
}  // namespace rover::runtime
