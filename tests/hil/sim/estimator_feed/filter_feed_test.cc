#include "hil/sim/estimator_feed/filter_feed.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <type_traits>
#include <variant>
#include <vector>

#include "core/geometry/so3.h"
#include "drivers/can/canopen_wheel_protocol.h"
#include "hil/sim/sensors/gpio_edge_model.h"
#include "hil/sim/sensors/imu_model.h"

namespace rover::sim {
namespace {

using estimator::CloneTrigger;
using estimator::EskfInput;
using estimator::FrameSwitchRequest;
using estimator::ImuMeasurement;
using estimator::RelativePoseMeasurement;
using estimator::WheelSpeedMeasurement;

Scenario Short() {
  return LoadScenario(FindScenario(DefaultScenarioDir(), "short"), DefaultSimConfigDir());
}

// One feed of the whole `short` scenario, shared by the tests (the world
// generation dominates the cost).
const FilterFeed& ShortFeed() {
  static const FilterFeed feed(Short(), 1);
  return feed;
}

template <typename T>
std::vector<T> All(const FilterFeed& feed) {
  std::vector<T> out;
  for (const EskfInput& in : feed.inputs()) {
    if (const T* m = std::get_if<T>(&in)) out.push_back(*m);
  }
  return out;
}

// Every number an input carries, with its kind, for exact comparisons.
std::vector<double> Fingerprint(const EskfInput& input) {
  std::vector<double> v{static_cast<double>(input.index()),
                        static_cast<double>(estimator::StampOf(input).nanoseconds())};
  std::visit(
      [&v](const auto& m) {
        using M = std::decay_t<decltype(m)>;
        if constexpr (std::is_same_v<M, ImuMeasurement>) {
          for (int i = 0; i < 3; ++i) v.push_back(m.angular_velocity_rad_s(i));
          for (int i = 0; i < 3; ++i) v.push_back(m.linear_acceleration_m_s2(i));
        } else if constexpr (std::is_same_v<M, WheelSpeedMeasurement>) {
          for (double w : m.wheel_rate_rad_s) v.push_back(w);
        } else if constexpr (std::is_same_v<M, RelativePoseMeasurement>) {
          v.push_back(static_cast<double>(m.from_stamp.nanoseconds()));
          v.push_back(static_cast<double>(m.to_stamp.nanoseconds()));
          for (int i = 0; i < 3; ++i) v.push_back(m.p_from_to(i));
          for (int i = 0; i < 4; ++i) v.push_back(m.q_from_to.coeffs()(i));
          for (int i = 0; i < 36; ++i) v.push_back(m.covariance(i));
          v.push_back(m.to_is_keyframe ? 1.0 : 0.0);
          v.push_back(static_cast<double>(m.oldest_keyframe_stamp.nanoseconds()));
        }
      },
      input);
  return v;
}

std::vector<std::vector<double>> Fingerprints(const FilterFeed& feed) {
  std::vector<std::vector<double>> out;
  for (const EskfInput& in : feed.inputs()) out.push_back(Fingerprint(in));
  return out;
}

TEST(FilterFeedTest, DeterministicForASeedAndDifferentForAnother) {
  // A second, shorter feed of the same seed repeats the full feed's inputs
  // exactly up to its end; another seed differs.
  FilterFeedOptions o;
  o.max_duration_s = 8.0;
  const auto a = Fingerprints(FilterFeed(Short(), 1, o));
  const auto c = Fingerprints(FilterFeed(Short(), 2, o));
  const auto full = Fingerprints(ShortFeed());
  ASSERT_GT(a.size(), 3000u);
  ASSERT_GT(full.size(), a.size());
  std::size_t same = 0;
  while (same < a.size() && a[same] == full[same]) ++same;
  // Identical up to the end (a SYNC whose TPDOs fall after the end of the
  // short feed is the only possible difference).
  EXPECT_GE(same + 1, a.size());
  ASSERT_GT(c.size(), 3000u);
  std::size_t differ = 0;
  for (std::size_t i = 0; i < std::min(a.size(), c.size()); ++i) differ += a[i] != c[i];
  EXPECT_GT(differ, a.size() / 2);  // IMU noise and world differ everywhere
}

TEST(FilterFeedTest, SortedByStampWithImuFirstAtEqualStamps) {
  const auto& in = ShortFeed().inputs();
  ASSERT_GT(in.size(), 1000u);
  for (std::size_t i = 1; i < in.size(); ++i) {
    const Time a = estimator::StampOf(in[i - 1]);
    const Time b = estimator::StampOf(in[i]);
    ASSERT_LE(a, b) << i;
    if (a == b) {
      ASSERT_FALSE(std::holds_alternative<ImuMeasurement>(in[i]) &&
                   !std::holds_alternative<ImuMeasurement>(in[i - 1]))
          << "IMU after another input at the same stamp, index " << i;
    }
  }
}

TEST(FilterFeedTest, HoldsEveryStreamAtItsRate) {
  const FilterFeed& feed = ShortFeed();
  const double duration_s = (feed.end() - feed.start()).ToSeconds();
  EXPECT_NEAR(duration_s, feed.trajectory().duration_s(), 1e-6);
  const auto& c = feed.counts();
  EXPECT_NEAR(static_cast<double>(c.imu), duration_s * 400.0, 2.0);
  EXPECT_NEAR(static_cast<double>(c.wheel_speeds), duration_s * 100.0, 2.0);
  EXPECT_NEAR(static_cast<double>(c.clone_triggers), duration_s * 10.0, 2.0);
  EXPECT_EQ(c.frame_switches, 0u);
  EXPECT_EQ(All<ImuMeasurement>(feed).size(), c.imu);
  EXPECT_EQ(All<WheelSpeedMeasurement>(feed).size(), c.wheel_speeds);
  EXPECT_EQ(All<CloneTrigger>(feed).size(), c.clone_triggers);
  EXPECT_EQ(All<RelativePoseMeasurement>(feed).size(), c.relative_poses);
  // Every frame after the start delay but the first keyframe yields one
  // measurement (minus those delivered after the end).
  EXPECT_NEAR(static_cast<double>(c.relative_poses), (duration_s - 1.5) * 10.0, 6.0);
  EXPECT_EQ(feed.imu_truth().size(), c.imu);
  EXPECT_EQ(feed.trigger_truth().size(), c.clone_triggers);
  EXPECT_NEAR(feed.distance_m(), feed.trajectory().distance_m(), 0.05);
}

TEST(FilterFeedTest, ImuSamplesAreTheSimulatorsOwn) {
  // GenerateDataset's recording rover: IMU seed = scenario seed ^ seed * golden ratio.
  const FilterFeed& feed = ShortFeed();
  ImuModelOptions o = feed.scenario().imu;
  o.seed = feed.scenario().imu.seed ^ (1 * 0x9E3779B97F4A7C15ULL);
  ImuModel imu(o, feed.start());
  const auto samples = All<ImuMeasurement>(feed);
  for (std::size_t i = 0; i < 2000; ++i) {
    TrajectorySample truth;
    const drivers::ImuSample s = imu.Next(feed.trajectory(), &truth);
    ASSERT_EQ(samples[i].stamp, s.stamp);
    ASSERT_EQ(samples[i].angular_velocity_rad_s, s.angular_velocity_rad_s);
    ASSERT_EQ(samples[i].linear_acceleration_m_s2, s.linear_acceleration_m_s2);
    ASSERT_EQ(feed.imu_truth()[i].p_world_body, truth.p_world_body);
    ASSERT_EQ(feed.imu_truth()[i].gyro_bias_rad_s, imu.gyro_bias_rad_s());
  }
}

TEST(FilterFeedTest, TruthAtTriggerTimesMatchesTheTrajectory) {
  const FilterFeed& feed = ShortFeed();
  const GpioEdgeModel gpio(feed.scenario().gpio, feed.start());
  const std::vector<Time> triggers = gpio.CameraTriggerTimes(feed.start(), feed.end());
  const auto clone_triggers = All<CloneTrigger>(feed);
  ASSERT_EQ(clone_triggers.size(), triggers.size());
  ASSERT_EQ(feed.trigger_truth().size(), triggers.size());
  EXPECT_EQ(triggers.front() - feed.start(), Duration::FromSeconds(0.0013));  // gpio.yaml phase
  for (std::size_t i = 0; i < triggers.size(); ++i) {
    EXPECT_EQ(clone_triggers[i].stamp, triggers[i]);
    const TruthSample& t = feed.trigger_truth()[i];
    const TrajectorySample s = feed.trajectory().Evaluate((triggers[i] - feed.start()).ToSeconds());
    EXPECT_EQ(t.stamp, triggers[i]);
    EXPECT_EQ(t.p_world_body, s.p_world_body);
    EXPECT_EQ(t.q_world_body.coeffs(), s.q_world_body.coeffs());
    EXPECT_EQ(t.v_world_m_s, s.v_world_m_s);
    const TruthSample at = feed.TruthAt(triggers[i]);
    EXPECT_EQ(at.p_world_body, t.p_world_body);
  }
  // The rover really moves between triggers (the lookup is not constant).
  EXPECT_GT(
      (feed.trigger_truth().back().p_world_body - feed.trigger_truth().front().p_world_body).norm(),
      2.0);
  // The IMU-rate truth is the same lookup at the sample stamps.
  for (std::size_t i = 0; i < feed.imu_truth().size(); i += 97) {
    const TruthSample& t = feed.imu_truth()[i];
    EXPECT_EQ(feed.TruthAt(t.stamp).p_world_body, t.p_world_body);
    EXPECT_EQ(feed.TruthAt(t.stamp).q_world_body.coeffs(), t.q_world_body.coeffs());
  }
}

TEST(FilterFeedTest, RelativePosesReferenceTriggersAndCarryTheStatedNoise) {
  const FilterFeed& feed = ShortFeed();
  std::set<Time> triggers;
  for (const CloneTrigger& t : All<CloneTrigger>(feed)) triggers.insert(t.stamp);
  const auto ms = All<RelativePoseMeasurement>(feed);
  ASSERT_GT(ms.size(), 400u);
  EXPECT_GE(ms.front().from_stamp - feed.start(), Duration::FromSeconds(1.5));
  double sum_d2 = 0.0;
  int keyframes = 0;
  for (std::size_t i = 0; i < ms.size(); ++i) {
    const RelativePoseMeasurement& m = ms[i];
    ASSERT_TRUE(triggers.count(m.from_stamp)) << i;
    ASSERT_TRUE(triggers.count(m.to_stamp)) << i;
    ASSERT_LT(m.from_stamp, m.to_stamp);
    const double latency = (m.stamp - m.to_stamp).ToSeconds();
    EXPECT_GE(latency, 0.05 - 1e-9);
    EXPECT_LE(latency, 0.45 + 1e-9);
    if (i > 0) {
      EXPECT_GT(m.to_stamp, ms[i - 1].to_stamp);
      EXPECT_GE(m.stamp, ms[i - 1].stamp);
      // Always from the latest keyframe.
      EXPECT_EQ(m.from_stamp, ms[i - 1].to_is_keyframe ? ms[i - 1].to_stamp : ms[i - 1].from_stamp);
    }
    keyframes += m.to_is_keyframe;
    const TruthSample a = feed.TruthAt(m.from_stamp);
    const TruthSample b = feed.TruthAt(m.to_stamp);
    const Eigen::Matrix3d Ra = a.q_world_body.toRotationMatrix();
    const Eigen::Matrix3d R_true = Ra.transpose() * b.q_world_body.toRotationMatrix();
    const Eigen::Vector3d p_true = Ra.transpose() * (b.p_world_body - a.p_world_body);
    Eigen::Matrix<double, 6, 1> n;
    n.head<3>() = m.p_from_to - p_true;
    n.tail<3>() = LogSO3(Eigen::Matrix3d(R_true.transpose() * m.q_from_to.toRotationMatrix()));
    sum_d2 += n.dot(m.covariance.ldlt().solve(n));
  }
  // chi2(6) mean over ~560 draws: std 0.15.
  EXPECT_NEAR(sum_d2 / static_cast<double>(ms.size()), 6.0, 0.6);
  // The drive has 0.3 m/s legs and turns: keyframes by distance and angle.
  EXPECT_GT(keyframes, 20);
  EXPECT_LT(keyframes, static_cast<int>(ms.size()) / 3);
}

TEST(FilterFeedTest, WheelSpeedsDecodedFromCanMatchTheModel) {
  const FilterFeed& feed = ShortFeed();
  const auto wheels = All<WheelSpeedMeasurement>(feed);
  ASSERT_EQ(wheels.size(), feed.wheel_truth().size());
  // Velocity noise 2 mrad/s (wheels.yaml) plus the 1 mrad/s TPDO unit.
  const double tolerance = 5.0 * feed.wheel_options().velocity_noise_sigma_rad_s + 0.0005;
  double max_rate = 0.0;
  bool turned = false;
  for (std::size_t i = 0; i < wheels.size(); ++i) {
    const WheelSyncState& truth = feed.wheel_truth()[i];
    ASSERT_EQ(wheels[i].stamp, truth.stamp);
    for (std::size_t w = 0; w < 4; ++w) {
      EXPECT_NEAR(wheels[i].wheel_rate_rad_s[w], truth.angular_velocity_rad_s[w], tolerance)
          << "sync " << i << " wheel " << w;
      max_rate = std::max(max_rate, std::abs(wheels[i].wheel_rate_rad_s[w]));
    }
    // Turning left on the spot: left wheels backwards, right ones forwards.
    const auto& r = wheels[i].wheel_rate_rad_s;
    if (r[estimator::kFrontLeft] < -0.3 && r[estimator::kRearLeft] < -0.3 &&
        r[estimator::kFrontRight] > 0.3 && r[estimator::kRearRight] > 0.3) {
      turned = true;
    }
  }
  EXPECT_GT(max_rate, 2.5);  // 0.3 m/s on 0.1 m wheels
  EXPECT_TRUE(turned);
}

TEST(FilterFeedTest, OptionsSwitchWheelsOffAndRequestFrameSwitches) {
  FilterFeedOptions o;
  o.wheels_enabled = false;
  o.frame_switch_distance_m = 2.0;
  o.max_duration_s = 30.0;
  const FilterFeed feed(Short(), 1, o);
  EXPECT_TRUE(All<WheelSpeedMeasurement>(feed).empty());
  EXPECT_EQ(feed.counts().wheel_speeds, 0u);
  EXPECT_FALSE(feed.wheel_truth().empty());  // the model still ran
  const auto switches = All<FrameSwitchRequest>(feed);
  ASSERT_EQ(switches.size(), feed.counts().frame_switches);
  EXPECT_EQ(switches.size(), static_cast<std::size_t>(std::floor(feed.distance_m() / 2.0)));
  ASSERT_FALSE(switches.empty());
  // Each at an IMU sample, where the distance passed the next multiple.
  std::set<Time> imu;
  for (const TruthSample& t : feed.imu_truth()) imu.insert(t.stamp);
  for (const FrameSwitchRequest& s : switches) EXPECT_TRUE(imu.count(s.stamp));
}

TEST(FilterFeedTest, LoadsAndValidatesOptions) {
  const ConfigNode node = ConfigNode::LoadString(
      "wheels_enabled: false\nframe_switch_distance_m: 7\nvo:\n  preset: realistic\n"
      "  drop_probability: 0.1\n",
      "feed.yaml");
  const FilterFeedOptions o = FilterFeedOptions::Load(node);
  node.CheckNoUnknownKeysRecursive();
  EXPECT_FALSE(o.wheels_enabled);
  EXPECT_EQ(o.frame_switch_distance_m, 7.0);
  EXPECT_EQ(o.vo.drop_probability, 0.1);
  EXPECT_EQ(o.vo.noise.rot_per_m, VoNoiseModel::Realistic().rot_per_m);
  EXPECT_THROW(FilterFeedOptions::Load(ConfigNode::LoadString("max_duration_s: -1\n", "x")),
               ConfigError);
  const ConfigNode typo = ConfigNode::LoadString("wheel_enabled: false\n", "y");
  FilterFeedOptions::Load(typo);
  EXPECT_THROW(typo.CheckNoUnknownKeysRecursive(), ConfigError);
  FilterFeedOptions bad;
  bad.vo.latency_max_s = 0.7;
  EXPECT_THROW(FilterFeed(Short(), 1, bad), std::invalid_argument);
}

}  // namespace
}  // namespace rover::sim
