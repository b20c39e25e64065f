#include "drivers/imu/clock_offset_tracker.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>

namespace rover::drivers {
namespace {

// A 400 Hz device whose clock runs `drift_ppm` fast, packets delayed by a
// constant 300 us plus exponential jitter (mean 400 us, tail to several ms):
// the stamps must follow the true sample times to within a few tens of us,
// while the raw receive times scatter by milliseconds.
void CheckTracking(double drift_ppm) {
  ClockOffsetTracker tracker;
  std::mt19937_64 rng(7);
  std::exponential_distribution<double> jitter_s(1.0 / 400e-6);
  const Time host_start = Time::FromSeconds(1000.0);
  const int64_t device_start_ns = 123'456'789;
  const double min_latency_s = 300e-6;
  Time last_stamp;
  double worst_stamp_error_s = 0.0, worst_receive_error_s = 0.0;
  for (int k = 0; k < 4000; ++k) {
    const double t_s = k / 400.0;  // true sample time since start, host clock
    const auto device_ns =
        device_start_ns + static_cast<int64_t>(std::llround(t_s * (1.0 + drift_ppm * 1e-6) * 1e9));
    const Time truth = host_start + Duration::FromSeconds(t_s);
    const Time receive = truth + Duration::FromSeconds(min_latency_s + jitter_s(rng));
    const Time stamp = tracker.Update(device_ns, receive);
    ASSERT_LE(stamp, receive) << "k " << k;
    if (k > 0) {
      ASSERT_GT(stamp, last_stamp) << "k " << k;
    }
    last_stamp = stamp;
    if (k >= 400) {  // after one second
      const double error_s = (stamp - truth).ToSeconds() - min_latency_s;
      worst_stamp_error_s = std::max(worst_stamp_error_s, std::abs(error_s));
      worst_receive_error_s =
          std::max(worst_receive_error_s, (receive - truth).ToSeconds() - min_latency_s);
    }
  }
  EXPECT_LT(worst_stamp_error_s, 80e-6) << "drift " << drift_ppm << " ppm";
  EXPECT_GT(worst_receive_error_s, 2e-3);  // what stamping with receive times would give
}

TEST(ClockOffsetTrackerTest, KeepsSerialJitterOutOfTheStamps) { CheckTracking(0.0); }
TEST(ClockOffsetTrackerTest, FollowsADeviceClockRunningFast) { CheckTracking(80.0); }
TEST(ClockOffsetTrackerTest, FollowsADeviceClockRunningSlow) { CheckTracking(-80.0); }

TEST(ClockOffsetTrackerTest, StartsOverWhenTheDeviceClockGoesBack) {
  ClockOffsetTrackerOptions no_rise;
  no_rise.max_drift_ppm = 0.0;
  ClockOffsetTracker tracker(no_rise);
  const Time t0 = Time::FromSeconds(50.0);
  EXPECT_EQ(tracker.Update(1'000'000'000, t0), t0);
  EXPECT_EQ(tracker.Update(1'002'500'000, t0 + Duration::Microseconds(2600)),
            t0 + Duration::Microseconds(2500));
  EXPECT_EQ(tracker.resets(), 0u);
  // Device restarted: its clock is back near zero.
  const Time t1 = t0 + Duration::Milliseconds(10);
  EXPECT_EQ(tracker.Update(5'000, t1), t1);
  EXPECT_EQ(tracker.resets(), 1u);
}

TEST(ClockOffsetTrackerTest, ValidatesItsOptions) {
  ClockOffsetTrackerOptions options;
  options.max_drift_ppm = -1.0;
  try {
    ClockOffsetTracker tracker(options);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("max_drift_ppm"), std::string::npos);
  }
}

}  // namespace
}  // namespace rover::drivers
