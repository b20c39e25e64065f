#include "firmware/runtime/rt/loop_probe.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <memory>

#include "tests/support/allocation_counter.h"

namespace rover::runtime {
namespace {

constexpr Duration kPeriod = Duration::Microseconds(2'500);  // 400 Hz
constexpr int64_t kUs = 1'000;

Time Deadline(int64_t k) { return Time::FromNanoseconds(1'000'000'000) + kPeriod * k; }

TEST(LoopProbeTest, RecordsWakeLatencyJitterAndSampleToEstimate) {
  auto probe = std::make_unique<LoopProbe>(kPeriod);
  // Wake-up latencies 10, 30, 20 us on consecutive slots.
  probe->OnWake(Deadline(0), Deadline(0) + Duration::Microseconds(10));
  probe->OnWake(Deadline(1), Deadline(1) + Duration::Microseconds(30));
  probe->OnWake(Deadline(2), Deadline(2) + Duration::Microseconds(20));
  probe->OnEstimatePublished(Deadline(2), Deadline(2) + Duration::Microseconds(45));

  const LoopProbeSnapshot s = probe->Snapshot();
  EXPECT_EQ(s.ticks, 3u);
  EXPECT_EQ(s.missed_periods, 0u);
  EXPECT_EQ(s.wakeup_latency.count, 3u);
  EXPECT_EQ(s.wakeup_latency.min_ns, 10 * kUs);
  EXPECT_EQ(s.wakeup_latency.max_ns, 30 * kUs);
  EXPECT_EQ(s.wakeup_latency.p50_ns, 20 * kUs);
  // Periods 2520 and 2490 us against 2500: |+20| and |-10|.
  EXPECT_EQ(s.period_jitter.count, 2u);
  EXPECT_EQ(s.period_jitter.min_ns, 10 * kUs);
  EXPECT_EQ(s.period_jitter.max_ns, 20 * kUs);
  EXPECT_EQ(s.sample_to_estimate.count, 1u);
  EXPECT_EQ(s.sample_to_estimate.max_ns, 45 * kUs);
}

TEST(LoopProbeTest, JitterAcrossSkippedSlotsUsesTheScheduledSpan) {
  auto probe = std::make_unique<LoopProbe>(kPeriod);
  probe->OnWake(Deadline(0), Deadline(0) + Duration::Microseconds(5));
  // Slots 1 and 2 were skipped by an overrun; slot 3 was served 400 us late.
  PeriodicTimer::Tick tick;
  tick.index = 3;
  tick.deadline = Deadline(3);
  tick.woke = Deadline(3) + Duration::Microseconds(400);
  tick.missed_periods = 2;
  tick.slept = false;
  probe->OnWake(tick);
  const LoopProbeSnapshot s = probe->Snapshot();
  EXPECT_EQ(s.missed_periods, 2u);
  EXPECT_EQ(s.period_jitter.max_ns, 395 * kUs);  // 7895 us against 3 x 2500 us
  // The late slot had no wake-up: counted, not put in the wake-up histogram.
  EXPECT_EQ(s.late_ticks, 1u);
  EXPECT_EQ(s.ticks, 2u);
  EXPECT_EQ(s.wakeup_latency.count, 1u);
  EXPECT_EQ(s.wakeup_latency.max_ns, 5 * kUs);
}

TEST(LoopProbeTest, LateSlotStillCountsInSampleToEstimate) {
  auto probe = std::make_unique<LoopProbe>(kPeriod);
  probe->OnWake(Deadline(4), Deadline(4) + Duration::Microseconds(900), 3, /*slept=*/false);
  probe->OnEstimatePublished(Deadline(4), Deadline(4) + Duration::Microseconds(915));
  const LoopProbeSnapshot s = probe->Snapshot();
  EXPECT_EQ(s.wakeup_latency.count, 0u);
  EXPECT_EQ(s.sample_to_estimate.max_ns, 915 * kUs);
}

TEST(LoopProbeTest, ResetStartsOver) {
  auto probe = std::make_unique<LoopProbe>(kPeriod);
  probe->OnWake(Deadline(0), Deadline(0) + Duration::Microseconds(5));
  probe->OnWake(Deadline(1), Deadline(1) + Duration::Microseconds(5));
  probe->Reset();
  probe->OnWake(Deadline(9), Deadline(9) + Duration::Microseconds(8));
  const LoopProbeSnapshot s = probe->Snapshot();
  EXPECT_EQ(s.ticks, 1u);
  EXPECT_EQ(s.wakeup_latency.count, 1u);
  EXPECT_EQ(s.period_jitter.count, 0u);  // no previous wake-up after a reset
}

TEST(LoopProbeTest, UpdatesAndSnapshotNeverAllocate) {
  auto probe = std::make_unique<LoopProbe>(kPeriod);
  testing::ScopedAllocationCheck check;
  for (int64_t k = 0; k < 10'000; ++k) {
    const Time woke = Deadline(k) + Duration::Nanoseconds(3'000 + (k * 7919) % 50'000);
    probe->OnWake(Deadline(k), woke);
    probe->OnEstimatePublished(Deadline(k), woke + Duration::Microseconds(12));
  }
  const LoopProbeSnapshot s = probe->Snapshot();
  EXPECT_EQ(check.allocations(), 0u);
  EXPECT_EQ(s.ticks, 10'000u);
}

}  // namespace
}  // namespace rover::runtime
