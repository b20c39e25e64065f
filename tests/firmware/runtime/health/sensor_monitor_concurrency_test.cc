// A driver thread feeding a SensorMonitor while the health thread takes
// snapshots, as in roverd. Run under TSan (label tsan) to prove the
// single-writer protocol race-free; the assertions check that no snapshot
// is torn and that the counters lose nothing.

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <thread>

#include "firmware/runtime/health/sensor_monitor.h"

namespace rover::runtime {
namespace {

TEST(SensorMonitorConcurrencyTest, SnapshotsWhileProducingAreConsistentAndLoseNoCount) {
  constexpr uint64_t kSamples = 200'000;
  constexpr uint64_t kDropEvery = 1'000;
  constexpr int64_t kLatencyNs = 250'000;
  SensorMonitor imu("imu", 1000.0);
  std::atomic<bool> done{false};

  std::thread producer([&] {
    Time stamp = Time::FromSeconds(10.0);
    for (uint64_t i = 1; i <= kSamples; ++i) {
      imu.OnSample(stamp, stamp + Duration::Nanoseconds(kLatencyNs));
      if (i % kDropEvery == 0) imu.OnDrop();
      stamp += Duration::Milliseconds(1);
    }
    done.store(true, std::memory_order_release);
  });

  // Reader: the health thread. Its clock is synthetic; only the counters
  // and latency values are checked.
  uint64_t snapshots = 0;
  uint64_t latency_samples = 0;
  uint64_t previous_samples = 0;
  uint64_t previous_drops = 0;
  bool torn = false;
  bool went_backwards = false;
  Time now = Time::FromSeconds(10.0);
  while (!done.load(std::memory_order_acquire)) {
    now += Duration::Milliseconds(1);
    const SensorHealth h = imu.Snapshot(now);
    ++snapshots;
    latency_samples += h.latency.count;
    // Every latency is exactly 250 us: any other summary value means a
    // snapshot mixed a cleared histogram with a filled one.
    if (h.latency.count > 0 && (h.latency.min_ns != kLatencyNs || h.latency.p50_ns != kLatencyNs ||
                                h.latency.p99_ns != kLatencyNs || h.latency.max_ns != kLatencyNs)) {
      torn = true;
    }
    if (h.samples < previous_samples || h.drops < previous_drops ||
        h.drops > h.samples / kDropEvery) {
      went_backwards = true;
    }
    previous_samples = h.samples;
    previous_drops = h.drops;
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
  producer.join();

  EXPECT_FALSE(torn);
  EXPECT_FALSE(went_backwards);
  // After the join the totals are exact.
  const SensorHealth final_health = imu.Snapshot(now + Duration::Milliseconds(1));
  ++snapshots;
  latency_samples += final_health.latency.count;
  EXPECT_EQ(final_health.samples, kSamples);
  EXPECT_EQ(final_health.drops, kSamples / kDropEvery);
  EXPECT_EQ(final_health.gaps, 0u);
  // The interval percentiles may miss the one producer call under way while
  // a snapshot closes its interval, never more, and never count twice.
  EXPECT_LE(latency_samples, kSamples);
  EXPECT_GE(latency_samples + snapshots, kSamples) << snapshots << " snapshots";

  // The main thread now owns the producer role (the join orders it after
  // the producer thread): a fresh interval counts exactly its samples.
  Time stamp = Time::FromSeconds(1000.0);
  for (int i = 0; i < 7; ++i) {
    imu.OnSample(stamp, stamp + Duration::Nanoseconds(kLatencyNs));
    stamp += Duration::Milliseconds(1);
  }
  EXPECT_EQ(imu.Snapshot(stamp).latency.count, 7u);
}

}  // namespace
}  // namespace rover::runtime
