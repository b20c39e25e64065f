#include "firmware/runtime/health/sensor_monitor.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>

#include "tests/support/allocation_counter.h"

namespace rover::runtime {
namespace {

// Every test uses synthetic stamps on a made-up monotonic clock starting at
// 100 s, so results do not depend on this machine's speed.
const Time kStart = Time::FromSeconds(100.0);

// Feeds `count` samples stamped every `period` from `first`, each arriving
// `latency` after its stamp. Returns the stamp after the last one.
Time Feed(SensorMonitor& monitor, Time first, Duration period, int count,
          Duration latency = Duration::Microseconds(100)) {
  Time stamp = first;
  for (int i = 0; i < count; ++i) {
    monitor.OnSample(stamp, stamp + latency);
    stamp += period;
  }
  return stamp;
}

TEST(SensorMonitorTest, SteadyStreamIsOkWithItsNominalRateAndLatency) {
  SensorMonitor imu("imu", 400.0);
  const Duration period = Duration::FromSeconds(1.0 / 400.0);
  // 401 samples: the first marks the start of the rate window, 400 more
  // span exactly 1 s.
  Feed(imu, kStart, period, 401);
  const Time last_arrival = kStart + period * 400 + Duration::Microseconds(100);
  const SensorHealth h = imu.Snapshot(last_arrival);

  EXPECT_EQ(h.name, "imu");
  EXPECT_EQ(h.level, HealthLevel::kOk);
  EXPECT_EQ(h.samples, 401u);
  EXPECT_EQ(h.rate_window_samples, 400u);
  EXPECT_DOUBLE_EQ(h.rate_window_s, 1.0);
  EXPECT_DOUBLE_EQ(h.rate_hz, 400.0);
  EXPECT_TRUE(h.rate_judged);
  EXPECT_FALSE(h.rate_low);
  EXPECT_EQ(h.gaps, 0u);
  EXPECT_EQ(h.drops, 0u);
  EXPECT_EQ(h.errors, 0u);
  EXPECT_TRUE(h.has_sample);
  EXPECT_DOUBLE_EQ(h.since_last_sample_s, 0.0);
  EXPECT_DOUBLE_EQ(h.interval_s, 0.0);  // First snapshot: no previous one.
  EXPECT_TRUE(h.latency_measured);
  EXPECT_EQ(h.latency.count, 401u);
  EXPECT_EQ(h.latency.p50_ns, 100'000);
  EXPECT_EQ(h.latency.p99_ns, 100'000);
  EXPECT_EQ(h.latency.max_ns, 100'000);
}

TEST(SensorMonitorTest, NoSampleEverIsStale) {
  SensorMonitor can("can", 100.0);
  const SensorHealth h = can.Snapshot(kStart);
  EXPECT_EQ(h.level, HealthLevel::kStale);
  EXPECT_FALSE(h.has_sample);
  EXPECT_TRUE(std::isinf(h.since_last_sample_s));
  EXPECT_EQ(h.samples, 0u);
  EXPECT_EQ(h.latency.count, 0u);
  EXPECT_DOUBLE_EQ(h.rate_hz, 0.0);
  EXPECT_FALSE(h.rate_judged);
}

TEST(SensorMonitorTest, StaleOnlyAfterMoreThanStaleAfterWithoutSample) {
  SensorMonitorOptions options;
  options.stale_after = Duration::Milliseconds(500);
  options.rate_warn_fraction = 0.0;  // Only staleness matters here.
  SensorMonitor can("can", 100.0, options);
  Feed(can, kStart, Duration::Milliseconds(10), 100, Duration::Zero());
  const Time last = kStart + Duration::Milliseconds(990);

  EXPECT_EQ(can.Snapshot(last + Duration::Milliseconds(500)).level, HealthLevel::kOk);
  const SensorHealth stale =
      can.Snapshot(last + Duration::Milliseconds(500) + Duration::Nanoseconds(1));
  EXPECT_EQ(stale.level, HealthLevel::kStale);
  EXPECT_NEAR(stale.since_last_sample_s, 0.5, 1e-6);

  // A new sample ends staleness at once; the silence shows as a gap.
  can.OnSample(last + Duration::Seconds(1), last + Duration::Seconds(1));
  const SensorHealth back = can.Snapshot(last + Duration::Seconds(1));
  EXPECT_EQ(back.level, HealthLevel::kWarn);
  EXPECT_EQ(back.new_gaps, 1u);
  EXPECT_DOUBLE_EQ(back.longest_gap_s, 1.0);
}

TEST(SensorMonitorTest, DropsWarnForOneIntervalAndStayInTheTotal) {
  SensorMonitor imu("imu", 100.0);
  const Duration period = Duration::Milliseconds(10);
  Time stamp = Feed(imu, kStart, period, 101);
  imu.OnDrop(3);
  SensorHealth h = imu.Snapshot(stamp);
  EXPECT_EQ(h.level, HealthLevel::kWarn);
  EXPECT_EQ(h.drops, 3u);
  EXPECT_EQ(h.new_drops, 3u);

  stamp = Feed(imu, stamp, period, 100);
  h = imu.Snapshot(stamp);
  EXPECT_EQ(h.level, HealthLevel::kOk);
  EXPECT_EQ(h.drops, 3u);
  EXPECT_EQ(h.new_drops, 0u);
  EXPECT_DOUBLE_EQ(h.interval_s, 1.0);
}

TEST(SensorMonitorTest, ErrorsOutrankDropsAndGaps) {
  SensorMonitor imu("imu", 100.0);
  const Duration period = Duration::Milliseconds(10);
  Time stamp = Feed(imu, kStart, period, 50);
  stamp = Feed(imu, stamp + period, period, 50);  // One missing sample: a gap.
  imu.OnDrop();
  imu.OnError();
  imu.OnError();
  const SensorHealth h = imu.Snapshot(stamp);
  EXPECT_EQ(h.level, HealthLevel::kError);
  EXPECT_EQ(h.new_errors, 2u);
  EXPECT_EQ(h.new_drops, 1u);
  EXPECT_EQ(h.new_gaps, 1u);

  // A single new error is enough; old ones no longer count.
  stamp = Feed(imu, stamp, period, 100);
  imu.OnError();
  SensorHealth next = imu.Snapshot(stamp);
  EXPECT_EQ(next.level, HealthLevel::kError);
  EXPECT_EQ(next.new_errors, 1u);
  EXPECT_EQ(next.errors, 3u);
  stamp = Feed(imu, stamp, period, 100);
  next = imu.Snapshot(stamp);
  EXPECT_EQ(next.level, HealthLevel::kOk);
  EXPECT_EQ(next.new_errors, 0u);
}

TEST(SensorMonitorTest, GapIsAStampIntervalLongerThanOneAndAHalfPeriods) {
  SensorMonitor camera("camera", 10.0);
  Time stamp = kStart;
  camera.OnSample(stamp, stamp);
  stamp += Duration::Milliseconds(150);  // Exactly 1.5 periods: jitter, not a gap.
  camera.OnSample(stamp, stamp);
  SensorHealth h = camera.Snapshot(stamp);
  EXPECT_EQ(h.gaps, 0u);
  EXPECT_EQ(h.level, HealthLevel::kOk);

  stamp += Duration::Milliseconds(150) + Duration::Nanoseconds(1);
  camera.OnSample(stamp, stamp);
  stamp += Duration::Milliseconds(400);  // Three samples missing.
  camera.OnSample(stamp, stamp);
  h = camera.Snapshot(stamp);
  EXPECT_EQ(h.gaps, 2u);
  EXPECT_EQ(h.new_gaps, 2u);
  EXPECT_DOUBLE_EQ(h.longest_gap_s, 0.4);
  EXPECT_EQ(h.level, HealthLevel::kWarn);
}

TEST(SensorMonitorTest, LowRateWarnsOnlyBelowTheWarnFraction) {
  const Duration window = Duration::Seconds(1);
  {
    SensorMonitor slow("wheels", 100.0);
    Feed(slow, kStart, Duration::FromSeconds(1.0 / 80.0), 81, Duration::Zero());  // 80 Hz, 1 s.
    const SensorHealth h = slow.Snapshot(kStart + window);
    EXPECT_TRUE(h.rate_judged);
    EXPECT_TRUE(h.rate_low);
    EXPECT_NEAR(h.rate_hz, 80.0, 1e-9);
    EXPECT_EQ(h.level, HealthLevel::kWarn);
    EXPECT_EQ(h.gaps, 0u);  // 12.5 ms < 15 ms: slow, but no single gap.
  }
  {
    SensorMonitor fine("wheels", 100.0);
    Feed(fine, kStart, Duration::FromSeconds(1.0 / 91.0), 92, Duration::Zero());  // Above 90 %.
    const SensorHealth h = fine.Snapshot(kStart + window);
    EXPECT_TRUE(h.rate_judged);
    EXPECT_FALSE(h.rate_low);
    EXPECT_EQ(h.level, HealthLevel::kOk);
  }
  {
    SensorMonitorOptions options;
    options.rate_warn_fraction = 0.0;  // Rate check off.
    options.gap_factor = 3.0;          // 20 ms spacing is no gap either.
    SensorMonitor unchecked("wheels", 100.0, options);
    Feed(unchecked, kStart, Duration::FromSeconds(1.0 / 50.0), 51, Duration::Zero());
    EXPECT_EQ(unchecked.Snapshot(kStart + window).level, HealthLevel::kOk);
  }
}

TEST(SensorMonitorTest, RateWindowSpansSnapshotsUntilTwentyPeriods) {
  // 10 Hz with 1 s snapshots: a window must span 2 s before it is judged.
  SensorMonitor camera("camera", 10.0);
  const Duration period = Duration::Milliseconds(100);
  Time stamp = Feed(camera, kStart, period, 11, Duration::Zero());  // First arrival at kStart.
  SensorHealth h = camera.Snapshot(kStart + Duration::Seconds(1));
  EXPECT_FALSE(h.rate_judged);
  EXPECT_FALSE(h.rate_low);
  EXPECT_DOUBLE_EQ(h.rate_window_s, 1.0);
  EXPECT_EQ(h.rate_window_samples, 10u);

  // Only 5 samples in the second second: judged over both, 15 in 2 s.
  Feed(camera, stamp, Duration::Milliseconds(110), 5, Duration::Zero());
  h = camera.Snapshot(kStart + Duration::Seconds(2));
  EXPECT_TRUE(h.rate_judged);
  EXPECT_DOUBLE_EQ(h.rate_window_s, 2.0);
  EXPECT_EQ(h.rate_window_samples, 15u);
  EXPECT_DOUBLE_EQ(h.rate_hz, 7.5);
  EXPECT_TRUE(h.rate_low);
  EXPECT_EQ(h.level, HealthLevel::kWarn);

  // A new window starts at the judged snapshot.
  h = camera.Snapshot(kStart + Duration::Milliseconds(2500));
  EXPECT_FALSE(h.rate_judged);
  EXPECT_DOUBLE_EQ(h.rate_window_s, 0.5);
  EXPECT_EQ(h.rate_window_samples, 0u);
}

TEST(SensorMonitorTest, LatencyPercentilesCoverOnlyTheirInterval) {
  SensorMonitor imu("imu", 100.0);
  const Duration period = Duration::Milliseconds(10);
  Time stamp = Feed(imu, kStart, period, 100, Duration::Microseconds(100));
  SensorHealth h = imu.Snapshot(stamp);
  EXPECT_EQ(h.latency.count, 100u);
  EXPECT_EQ(h.latency.max_ns, 100'000);

  // 98 samples at 200 us and 2 at 900 us: p50 200 us, p99 and max 900 us.
  stamp = Feed(imu, stamp, period, 98, Duration::Microseconds(200));
  stamp = Feed(imu, stamp, period, 2, Duration::Microseconds(900));
  h = imu.Snapshot(stamp);
  EXPECT_EQ(h.latency.count, 100u);
  EXPECT_EQ(h.latency.min_ns, 200'000);
  EXPECT_EQ(h.latency.p50_ns, 200'000);
  EXPECT_EQ(h.latency.p99_ns, 900'000);
  EXPECT_EQ(h.latency.max_ns, 900'000);

  // An interval without samples reports no latency, not the histogram of
  // two intervals ago (which shares its buffer).
  h = imu.Snapshot(stamp + Duration::Milliseconds(500));
  EXPECT_EQ(h.latency.count, 0u);
  EXPECT_EQ(h.latency.max_ns, 0);

  // And the buffer is cleared when used again.
  stamp = Feed(imu, stamp, period, 3, Duration::Microseconds(50));
  h = imu.Snapshot(stamp);
  EXPECT_EQ(h.latency.count, 3u);
  EXPECT_EQ(h.latency.max_ns, 50'000);
}

TEST(SensorMonitorTest, LatencyOffForStampsOnAnotherClock) {
  SensorMonitorOptions options;
  options.measure_latency = false;
  SensorMonitor camera("camera", 10.0, options);
  // Hardware stamps near 5 s, arrivals near 100 s: only the stamps' spacing
  // is meaningful (for gaps).
  const Time hw = Time::FromSeconds(5.0);
  camera.OnSample(hw, kStart);
  camera.OnSample(hw + Duration::Milliseconds(300), kStart + Duration::Milliseconds(300));
  const SensorHealth h = camera.Snapshot(kStart + Duration::Milliseconds(300));
  EXPECT_FALSE(h.latency_measured);
  EXPECT_EQ(h.latency.count, 0u);
  EXPECT_EQ(h.latency.max_ns, 0);
  EXPECT_EQ(h.gaps, 1u);
  EXPECT_DOUBLE_EQ(h.longest_gap_s, 0.3);
  EXPECT_DOUBLE_EQ(h.since_last_sample_s, 0.0);
}

TEST(SensorMonitorTest, ProducerPathNeverAllocates) {
  SensorMonitor imu("a_sensor_name_longer_than_the_small_string_buffer", 400.0);
  imu.Snapshot(kStart);  // Start a new interval, so the producer clears a histogram below.
  testing::ScopedAllocationCheck check;
  Time stamp = kStart;
  for (int i = 0; i < 1000; ++i) {
    imu.OnSample(stamp, stamp + Duration::Microseconds(80));
    if (i % 100 == 0) imu.OnDrop(2);
    if (i % 500 == 0) imu.OnError();
    stamp += Duration::Microseconds(2500);
  }
  EXPECT_EQ(check.allocations(), 0u);
}

TEST(SensorMonitorTest, InvalidConstructionThrows) {
  EXPECT_THROW(SensorMonitor("", 100.0), std::invalid_argument);
  EXPECT_THROW(SensorMonitor("imu", 0.0), std::invalid_argument);
  EXPECT_THROW(SensorMonitor("imu", -1.0), std::invalid_argument);
  EXPECT_THROW(SensorMonitor("imu", std::nan("")), std::invalid_argument);
  SensorMonitorOptions bad;
  bad.gap_factor = 0.5;
  EXPECT_THROW(SensorMonitor("imu", 100.0, bad), std::invalid_argument);
}

// Returns the message of the std::invalid_argument Validate() throws, or "".
std::string ValidationError(const SensorMonitorOptions& options) {
  try {
    options.Validate();
    return "";
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
}

TEST(SensorMonitorTest, OptionsValidationSaysWhatWasExpectedAndFound) {
  EXPECT_EQ(ValidationError(SensorMonitorOptions{}), "");
  SensorMonitorOptions o;
  o.stale_after = Duration::Zero();
  EXPECT_EQ(ValidationError(o),
            "SensorMonitorOptions.stale_after: expected a positive duration, found " +
                Duration::Zero().ToString());
  o = {};
  o.rate_warn_fraction = 1.5;
  EXPECT_EQ(ValidationError(o),
            "SensorMonitorOptions.rate_warn_fraction: expected a fraction in [0, 1], found "
            "1.500000");
  o = {};
  o.gap_factor = std::nan("");
  EXPECT_NE(ValidationError(o).find("SensorMonitorOptions.gap_factor: expected a finite number"),
            std::string::npos);
}

TEST(SensorMonitorTest, LevelNamesShoutOnlyProblems) {
  EXPECT_EQ(HealthLevelName(HealthLevel::kOk), "ok");
  EXPECT_EQ(HealthLevelName(HealthLevel::kWarn), "WARN");
  EXPECT_EQ(HealthLevelName(HealthLevel::kError), "ERROR");
  EXPECT_EQ(HealthLevelName(HealthLevel::kStale), "STALE");
}

}  // namespace
}  // namespace rover::runtime
