#include "drivers/camera/device_clock_fit.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <random>
#include <stdexcept>

#include "tests/support/allocation_counter.h"

namespace rover::drivers {
namespace {

using ::testing::HasSubstr;

// A simulated camera: its clock runs `drift_ppm` slow against the host's, so
// that host = h0 + (1 + drift) * (device - d0). Frames are received after a
// one-sided latency: a fixed minimum plus an exponential tail, and now and
// then a long scheduling stall.
class SimulatedLink {
 public:
  SimulatedLink(double drift_ppm, uint32_t seed) : drift_(drift_ppm * 1e-6), rng_(seed) {}

  /// True host time of device time `device_ns`.
  int64_t TrueHost(int64_t device_ns) const {
    const double x = static_cast<double>(device_ns - device0_ns_);
    return host0_ns_ + device_ns - device0_ns_ + std::llround(drift_ * x);
  }
  /// Device time of frame k at ~30 Hz with a little device-side jitter.
  int64_t Device(int k) {
    return device0_ns_ + static_cast<int64_t>(k) * 33'333'333 + jitter_(rng_);
  }
  /// Receive time: true + 150 us + Exp(mean 400 us), 5 % of them +5..40 ms.
  Time Receive(int64_t device_ns) {
    int64_t latency_ns = kMinLatencyNs + std::llround(tail_(rng_));
    if (stall_(rng_) < 0.05) latency_ns += std::llround(5e6 + 35e6 * stall_(rng_));
    return Time::FromNanoseconds(TrueHost(device_ns) + latency_ns);
  }

  static constexpr int64_t kMinLatencyNs = 150'000;
  // Realistic magnitudes: a device clock on the Unix epoch, a host clock
  // since boot. Their difference needs all 64 bits.
  int64_t device0_ns_ = 1'795'288'109'382'017'000;
  int64_t host0_ns_ = 56'202'341'616'165;

 private:
  double drift_;
  std::mt19937_64 rng_;
  std::uniform_int_distribution<int64_t> jitter_{-20'000, 20'000};
  std::exponential_distribution<double> tail_{1.0 / 400'000.0};
  std::uniform_real_distribution<double> stall_{0.0, 1.0};
};

// Largest |mapped - (true + minimum latency)| over frames [from, to).
struct FitRun {
  double max_error_us = 0.0;
  double drift_ppm = 0.0;
};

FitRun RunLink(double drift_ppm, uint32_t seed, int frames, DeviceClockFit* fit) {
  SimulatedLink link(drift_ppm, seed);
  FitRun run;
  for (int k = 0; k < frames; ++k) {
    const int64_t device = link.Device(k);
    fit->Add(device, link.Receive(device));
    if (k >= 600) {  // after 20 s (the window: 256 slots of 50 ms, 12.8 s)
      const int64_t expected = link.TrueHost(device) + SimulatedLink::kMinLatencyNs;
      const double error_us =
          std::abs(static_cast<double>(fit->ToHost(device).nanoseconds() - expected)) * 1e-3;
      run.max_error_us = std::max(run.max_error_us, error_us);
    }
  }
  run.drift_ppm = fit->drift_ppm();
  return run;
}

TEST(DeviceClockFitTest, RecoversOffsetAndFiftyPpmDriftFromOneSidedLatency) {
  for (uint32_t seed = 1; seed <= 5; ++seed) {
    DeviceClockFit fit;
    const FitRun run = RunLink(50.0, seed, 1500, &fit);
    SCOPED_TRACE(seed);
    // A least-squares line would sit ~400 us (the mean latency) above the
    // truth and be pulled by the 5 % stalls; the envelope stays within a few
    // microseconds of the minimum-latency line.
    EXPECT_NEAR(run.drift_ppm, 50.0, 5.0);
    EXPECT_LT(run.max_error_us, 40.0);
    EXPECT_GT(fit.outliers(), 0u);  // the stalls were seen, and ignored
    EXPECT_EQ(fit.resets(), 0u);
    EXPECT_GT(fit.mean_residual(), Duration::Microseconds(100));
    // offset() is host - device at the newest pair.
    SimulatedLink link(50.0, seed);
    const int64_t newest = link.Device(1499);
    const Duration expected_offset =
        Duration::Nanoseconds(link.TrueHost(newest) + SimulatedLink::kMinLatencyNs - newest);
    EXPECT_LT(std::abs((fit.offset() - expected_offset).ToMicroseconds()), 40.0);
  }
}

TEST(DeviceClockFitTest, NegativeDriftAndNoDrift) {
  for (const double ppm : {-80.0, 0.0}) {
    DeviceClockFit fit;
    const FitRun run = RunLink(ppm, 7, 1200, &fit);
    EXPECT_NEAR(run.drift_ppm, ppm, 5.0);
    EXPECT_LT(run.max_error_us, 40.0);
  }
}

TEST(DeviceClockFitTest, RejectsLateOutliersEvenWhenTheyDominate) {
  // 40 % of the frames arrive 25..60 ms late (a starved receive thread), in
  // bursts of two (shorter than reset_run_length): the envelope is made of
  // the punctual ones only.
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  DeviceClockFit fit;
  const int64_t d0 = 1'000'000'000'000;
  const int64_t h0 = 7'000'000'000;
  double max_error_us = 0.0;
  for (int k = 0; k < 400; ++k) {
    const int64_t d = d0 + int64_t{k} * 50'000'000;
    int64_t latency = 100'000 + std::llround(20'000 * u(rng));
    if (k % 5 < 2 && k > 3) latency += std::llround(25e6 + 35e6 * u(rng));
    fit.Add(d, Time::FromNanoseconds(h0 + (d - d0) + latency));
    if (k > 50) {
      const double e =
          std::abs(static_cast<double>(fit.ToHost(d).nanoseconds() - (h0 + (d - d0) + 100'000))) *
          1e-3;
      max_error_us = std::max(max_error_us, e);
    }
  }
  EXPECT_LT(max_error_us, 20.0);
  EXPECT_NEAR(fit.drift_ppm(), 0.0, 5.0);
  EXPECT_EQ(fit.resets(), 0u);
  EXPECT_GT(fit.outliers(), 150u);
  EXPECT_GT(fit.mean_residual(), Duration::Milliseconds(5));  // seen, yet without effect
}

TEST(DeviceClockFitTest, DeviceCounterResetRestartsTheFitAndKeepsTheDrift) {
  SimulatedLink link(50.0, 3);
  DeviceClockFit fit;
  for (int k = 0; k < 1000; ++k) {
    const int64_t d = link.Device(k);
    fit.Add(d, link.Receive(d));
  }
  ASSERT_NEAR(fit.drift_ppm(), 50.0, 5.0);
  const double drift_before_ppm = fit.drift_ppm();
  // The camera reboots: its counter restarts near zero while host time goes on.
  const int64_t host_at_reboot = link.TrueHost(link.Device(999)) + 2'000'000'000;
  std::mt19937_64 rng(5);
  std::exponential_distribution<double> tail(1.0 / 400'000.0);
  int resets_seen = 0;
  double max_error_us = 0.0;
  for (int k = 0; k < 100; ++k) {
    const int64_t d = 1'000 + int64_t{k} * 33'333'333;
    const int64_t true_host = host_at_reboot + d + std::llround(50e-6 * static_cast<double>(d));
    const auto result = fit.Add(d, Time::FromNanoseconds(true_host + SimulatedLink::kMinLatencyNs +
                                                         std::llround(tail(rng))));
    resets_seen += result == DeviceClockFit::AddResult::kReset ? 1 : 0;
    if (k >= 40) {
      const double e = std::abs(static_cast<double>(fit.ToHost(d).nanoseconds() -
                                                    (true_host + SimulatedLink::kMinLatencyNs))) *
                       1e-3;
      max_error_us = std::max(max_error_us, e);
    }
  }
  EXPECT_EQ(resets_seen, 1);
  EXPECT_EQ(fit.resets(), 1u);
  // 100 pairs (50 slots) do not fill the window: the old full-window drift
  // is kept.
  EXPECT_EQ(fit.drift_ppm(), drift_before_ppm);
  EXPECT_LT(max_error_us, 40.0);
}

TEST(DeviceClockFitTest, ForwardJumpOfTheDeviceClockIsAReset) {
  DeviceClockFit fit;
  for (int k = 0; k < 50; ++k) {
    const int64_t d = int64_t{k} * 10'000'000;
    fit.Add(d, Time::FromNanoseconds(d + 1'000'000'000 + 100'000));
  }
  // The device clock leaps 1 h ahead (re-synchronised by PTP, say): mapped
  // through the old fit the pair would be an hour early, which latency
  // cannot explain.
  const int64_t d = 3'600'000'000'000 + 50 * 10'000'000;
  EXPECT_EQ(fit.Add(d, Time::FromNanoseconds(50 * 10'000'000 + 1'000'000'000 + 100'000)),
            DeviceClockFit::AddResult::kReset);
  EXPECT_EQ(fit.size(), 1);
  EXPECT_EQ(fit.ToHost(d).nanoseconds(), 50 * 10'000'000 + 1'000'000'000 + 100'000);
}

TEST(DeviceClockFitTest, PersistentLateStepIsAResetAfterTheRun) {
  DeviceClockFitOptions options;
  options.reset_run_length = 4;
  DeviceClockFit fit(options);
  int64_t d = 0;
  for (int k = 0; k < 50; ++k, d += 10'000'000) {
    fit.Add(d, Time::FromNanoseconds(d + 100'000));
  }
  // Every pair is now 100 ms later (the host's receive stamp moved).
  for (int k = 0; k < 3; ++k, d += 10'000'000) {
    EXPECT_EQ(fit.Add(d, Time::FromNanoseconds(d + 100'100'000)),
              DeviceClockFit::AddResult::kOutlier);
  }
  EXPECT_EQ(fit.Add(d, Time::FromNanoseconds(d + 100'100'000)), DeviceClockFit::AddResult::kReset);
  d += 10'000'000;
  EXPECT_EQ(fit.Add(d, Time::FromNanoseconds(d + 100'100'000)),
            DeviceClockFit::AddResult::kAccepted);
  EXPECT_EQ(fit.ToHost(d).nanoseconds(), d + 100'100'000);
}

TEST(DeviceClockFitTest, DuplicateDeviceTimeIsIgnoredAndBackwardsIsAReset) {
  DeviceClockFit fit;
  EXPECT_FALSE(fit.valid());
  EXPECT_EQ(fit.Add(1'000, Time::FromNanoseconds(5'000)), DeviceClockFit::AddResult::kAccepted);
  EXPECT_TRUE(fit.valid());
  EXPECT_EQ(fit.Add(1'000, Time::FromNanoseconds(6'000)), DeviceClockFit::AddResult::kIgnored);
  EXPECT_EQ(fit.size(), 1);
  EXPECT_EQ(fit.Add(500, Time::FromNanoseconds(7'000)), DeviceClockFit::AddResult::kReset);
  EXPECT_EQ(fit.size(), 1);
  EXPECT_EQ(fit.ToHost(500).nanoseconds(), 7'000);
}

TEST(DeviceClockFitTest, ShortWindowFitsOffsetOnly) {
  // Two pairs 100 ms apart with different latencies must not produce a
  // 1000 ppm drift: below min_span_for_drift only the offset is fitted.
  DeviceClockFit fit;
  fit.Add(0, Time::FromNanoseconds(1'000'000));
  fit.Add(100'000'000, Time::FromNanoseconds(100'000'000 + 1'100'000));
  EXPECT_EQ(fit.size(), 2);
  EXPECT_EQ(fit.drift_ppm(), 0.0);
  EXPECT_EQ(fit.ToHost(0).nanoseconds(), 1'000'000);
  EXPECT_EQ(fit.last_residual(), Duration::Microseconds(100));
}

TEST(DeviceClockFitTest, PairsWithinTheSpacingShareASlotKeepingTheLeastLate) {
  DeviceClockFitOptions options;
  options.pair_spacing = Duration::Milliseconds(50);
  DeviceClockFit fit(options);
  // Three frames within 50 ms: latencies 300, 100 and 200 us.
  fit.Add(0, Time::FromNanoseconds(300'000));
  fit.Add(10'000'000, Time::FromNanoseconds(10'000'000 + 100'000));
  fit.Add(20'000'000, Time::FromNanoseconds(20'000'000 + 200'000));
  EXPECT_EQ(fit.size(), 1);
  EXPECT_EQ(fit.ToHost(0).nanoseconds(), 100'000);  // the 100 us one defines the envelope
  EXPECT_EQ(fit.last_residual(), Duration::Microseconds(100));
  fit.Add(50'000'000, Time::FromNanoseconds(50'000'000 + 150'000));
  EXPECT_EQ(fit.size(), 2);  // a new slot
}

TEST(DeviceClockFitTest, DriftIsClampedToTheConfiguredBound) {
  DeviceClockFitOptions options;
  options.max_drift_ppm = 100.0;
  options.min_span_for_drift = Duration::Zero();
  DeviceClockFit fit(options);
  for (int k = 0; k < 20; ++k) {
    const int64_t d = int64_t{k} * 100'000'000;
    fit.Add(d, Time::FromNanoseconds(d + d / 1000));  // 1000 ppm
  }
  EXPECT_DOUBLE_EQ(fit.drift_ppm(), 100.0);
}

TEST(DeviceClockFitTest, AddNeverAllocates) {
  DeviceClockFit fit;
  SimulatedLink link(50.0, 9);
  testing::ScopedAllocationCheck check;
  for (int k = 0; k < 1000; ++k) {
    const int64_t d = link.Device(k);
    fit.Add(d, link.Receive(d));
    (void)fit.ToHost(d);
  }
  EXPECT_EQ(check.allocations(), 0u);
}

TEST(DeviceClockFitTest, OptionsAreValidatedNamingTheField) {
  const auto message_of = [](const DeviceClockFitOptions& options) {
    try {
      DeviceClockFit fit(options);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no exception");
  };
  DeviceClockFitOptions options;
  options.window_size = 1;
  EXPECT_THAT(message_of(options), HasSubstr("window_size: expected 2..65536, found 1"));
  options = {};
  options.reset_threshold = Duration::Zero();
  EXPECT_THAT(message_of(options), HasSubstr("reset_threshold: expected > 0"));
  options = {};
  options.reset_run_length = 0;
  EXPECT_THAT(message_of(options), HasSubstr("reset_run_length"));
  options = {};
  options.max_drift_ppm = -1.0;
  EXPECT_THAT(message_of(options), HasSubstr("max_drift_ppm"));
  options = {};
  options.min_span_for_drift = Duration::Milliseconds(-1);
  EXPECT_THAT(message_of(options), HasSubstr("min_span_for_drift"));
}

}  // namespace
}  // namespace rover::drivers
