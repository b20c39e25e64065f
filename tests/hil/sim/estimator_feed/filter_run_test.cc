#include "hil/sim/estimator_feed/filter_run.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

namespace rover::sim {
namespace {

using estimator::InputKind;
using estimator::RejectReason;

Scenario Short() {
  return LoadScenario(FindScenario(DefaultScenarioDir(), "short"), DefaultSimConfigDir());
}

void Print(const char* name, const FilterRunResult& r) {
  std::printf(
      "[%s] outputs %llu, distance %.2f m, position error final %.4f m mean %.4f m max %.4f m "
      "(global final %.4f m mean %.4f m), attitude final %.4f deg, NEES pos %.2f att %.2f, "
      "VO accepted %llu rejected %llu (gated %llu), wheels rejected %llu, evicted clones %llu\n",
      name, static_cast<unsigned long long>(r.outputs), r.distance_m, r.final_position_error_m,
      r.mean_position_error_m, r.max_position_error_m, r.final_global_position_error_m,
      r.mean_global_position_error_m, r.final_attitude_error_rad * 180.0 / std::numbers::pi,
      r.mean_nees_position, r.mean_nees_attitude,
      static_cast<unsigned long long>(r.health.Accepted(InputKind::kRelativePose)),
      static_cast<unsigned long long>(r.RejectedAfterInit(InputKind::kRelativePose)),
      static_cast<unsigned long long>(
          r.health.Rejected(InputKind::kRelativePose, RejectReason::kGated)),
      static_cast<unsigned long long>(r.RejectedAfterInit(InputKind::kWheelSpeeds)),
      static_cast<unsigned long long>(r.health.clones_evicted));
}

TEST(FilterRunTest, OptionsFollowTheSimulatedSensors) {
  FilterFeedOptions fo;
  fo.max_duration_s = 3.0;
  fo.wheels_enabled = false;
  const FilterFeed feed(Short(), 1, fo);
  const estimator::EskfOptions o = EskfOptionsForFeed(feed);
  EXPECT_EQ(o.imu.rate_hz, feed.scenario().imu.rate_hz);
  EXPECT_EQ(o.imu.gyro_noise_density_rad_s_sqrt_hz, feed.scenario().imu.gyro.noise_density);
  EXPECT_EQ(o.imu.accel_bias_random_walk_m_s3_sqrt_hz, feed.scenario().imu.accel.bias_random_walk);
  EXPECT_EQ(o.imu.gyro_range_rad_s, feed.scenario().imu.gyro.range);
  EXPECT_EQ(o.imu.gravity_m_s2, kStandardGravity_m_s2);
  EXPECT_FALSE(o.wheels.enabled);
  EXPECT_EQ(o.wheels.wheel_radius_m, feed.trajectory().options().wheel_radius_m);
  EXPECT_EQ(o.wheels.track_m, feed.trajectory().options().track_m);
  EXPECT_EQ(o.wheels.yaw_scrub_factor, 1.3);  // hil/config/wheels.yaml
  // Wheel-axle centre: r - body height below the IMU.
  EXPECT_NEAR((o.wheels.lever_arm_body_m - Eigen::Vector3d(0, 0, 0.1 - 0.35)).norm(), 0.0, 1e-12);
}

// The filter alone on `short` with a consistent VO: the design's local
// accuracy bar is <= 1 % of the distance driven.
TEST(FilterRunTest, ShortWithIdealConsistentVoStaysWellWithinOnePercent) {
  FilterFeedOptions fo;
  fo.vo.noise = VoNoiseModel::IdealConsistent();
  const FilterFeed feed(Short(), 1, fo);
  const FilterRunResult r = RunFilter(feed, EskfOptionsForFeed(feed));
  Print("short ideal-consistent", r);
  ASSERT_GT(r.outputs, 20000u);
  EXPECT_TRUE(r.all_finite);
  EXPECT_TRUE(r.frame_ids_consistent);
  EXPECT_EQ(r.frame_switches, 0u);
  EXPECT_GT(r.distance_m, 10.0);
  EXPECT_LT(r.final_position_error_m, 0.005 * r.distance_m);
  EXPECT_LT(r.mean_position_error_m, 0.005 * r.distance_m);
  EXPECT_LT(r.final_global_position_error_m, 0.005 * r.distance_m);
  EXPECT_GT(r.health.Accepted(InputKind::kRelativePose), 450u);
}

TEST(FilterRunTest, FrameSwitchesChainIntoTheGlobalError) {
  FilterFeedOptions fo;
  fo.vo.noise = VoNoiseModel::IdealConsistent();
  fo.frame_switch_distance_m = 3.0;
  fo.max_duration_s = 40.0;
  const FilterFeed feed(Short(), 1, fo);
  const FilterRunResult r = RunFilter(feed, EskfOptionsForFeed(feed));
  Print("short ideal-consistent, switch every 3 m", r);
  EXPECT_TRUE(r.all_finite);
  EXPECT_TRUE(r.frame_ids_consistent);
  ASSERT_EQ(r.frame_switches, feed.counts().frame_switches);
  ASSERT_GE(r.frame_switches, 2u);
  // Right after a switch the per-frame error restarts from zero, the global
  // one does not.
  double max_gap = 0.0;
  for (const FilterErrorSample& s : r.samples) {
    if (s.frame_id == 0) {
      EXPECT_NEAR((s.dp_global_m - s.dp_local_m).norm(), 0.0, 1e-9);
    }
    max_gap = std::max(max_gap, (s.dp_global_m - s.dp_local_m).norm());
  }
  EXPECT_GT(max_gap, 0.0);
  for (const auto& sw : r.switches) {
    const auto it = std::find_if(r.samples.begin(), r.samples.end(),
                                 [&](const FilterErrorSample& s) { return s.stamp > sw.stamp; });
    ASSERT_NE(it, r.samples.end());
    EXPECT_LT(it->dp_local_m.norm(), 0.01);
  }
  EXPECT_LT(r.final_global_position_error_m, 0.01 * r.distance_m);
}

}  // namespace
}  // namespace rover::sim
