#include "hil/sim/estimator_feed/synthetic_vo.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <numbers>
#include <vector>

#include "core/config/config.h"
#include "core/geometry/so3.h"

namespace rover::sim {
namespace {

using estimator::RelativePoseMeasurement;

constexpr double kDeg = std::numbers::pi / 180.0;
const Time kT0 = Time::FromNanoseconds(1'000'000'000'000);
const Duration kFramePeriod = Duration::Milliseconds(100);

// Frames at 10 Hz: frame i at x = step_m * i, yaw = step_rad * i.
std::vector<VoFrame> Frames(int count, double step_m, double step_rad) {
  std::vector<VoFrame> frames;
  for (int i = 0; i < count; ++i) {
    VoFrame f;
    f.capture = kT0 + kFramePeriod * i;
    f.T_world_body.translation() = Eigen::Vector3d(step_m * i, 0.0, 0.0);
    f.T_world_body.linear() = ExpSO3(Eigen::Vector3d(0.0, 0.0, step_rad * i));
    frames.push_back(f);
  }
  return frames;
}

SyntheticVoOptions NoDelay() {
  SyntheticVoOptions o;
  o.start_delay_s = 0.0;
  return o;
}

// Capture times of the frames that became keyframes, in order.
std::vector<Time> KeyframeStamps(const std::vector<VoFrame>& frames,
                                 const std::vector<RelativePoseMeasurement>& ms) {
  std::vector<Time> kf{frames.front().capture};
  for (const auto& m : ms) {
    if (m.to_is_keyframe) kf.push_back(m.to_stamp);
  }
  return kf;
}

TEST(SyntheticVoTest, NewKeyframeWhenTheDistanceExceedsTheThreshold) {
  // 0.12 m per frame: 0.48 m after 4 frames, 0.60 m after 5.
  const auto frames = Frames(12, 0.12, 0.0);
  const auto ms = RunSyntheticVo(NoDelay(), frames, 1);
  ASSERT_EQ(ms.size(), 11u);
  for (std::size_t i = 0; i < ms.size(); ++i) {
    EXPECT_EQ(ms[i].to_stamp, frames[i + 1].capture);
    EXPECT_EQ(ms[i].to_is_keyframe, i == 4 || i == 9) << "frame " << i + 1;
    // Always from the latest keyframe.
    const std::size_t kf = i < 5 ? 0 : (i < 10 ? 5 : 10);
    EXPECT_EQ(ms[i].from_stamp, frames[kf].capture) << i;
  }
}

TEST(SyntheticVoTest, NewKeyframeWhenTheRotationExceedsTheThreshold) {
  // 3 deg per frame: 12 deg after 4 frames.
  const auto ms = RunSyntheticVo(NoDelay(), Frames(9, 0.0, 3.0 * kDeg), 1);
  ASSERT_EQ(ms.size(), 8u);
  for (std::size_t i = 0; i < ms.size(); ++i) {
    EXPECT_EQ(ms[i].to_is_keyframe, i == 3 || i == 7) << "frame " << i + 1;
  }
}

TEST(SyntheticVoTest, NewKeyframeAfterMaxFramesAtStandstill) {
  const auto ms = RunSyntheticVo(NoDelay(), Frames(25, 0.0, 0.0), 1);
  ASSERT_EQ(ms.size(), 24u);
  for (std::size_t i = 0; i < ms.size(); ++i) {
    EXPECT_EQ(ms[i].to_is_keyframe, (i + 1) % 10 == 0) << "frame " << i + 1;
  }
}

TEST(SyntheticVoTest, HoldsFiveKeyframesAndReportsTheOldest) {
  const auto frames = Frames(80, 0.0, 0.0);  // a keyframe every 10 frames
  const auto ms = RunSyntheticVo(NoDelay(), frames, 1);
  const std::vector<Time> kf = KeyframeStamps(frames, ms);
  ASSERT_EQ(kf.size(), 8u);
  std::size_t made = 1;
  for (const auto& m : ms) {
    if (m.to_is_keyframe) ++made;
    const std::size_t oldest = made > 5 ? made - 5 : 0;
    EXPECT_EQ(m.oldest_keyframe_stamp, kf[oldest]);
    EXPECT_LE(m.oldest_keyframe_stamp, m.from_stamp);
  }
}

TEST(SyntheticVoTest, FirstKeyframeAfterTheStartDelay) {
  SyntheticVoOptions o = NoDelay();
  o.start_delay_s = 1.45;
  const auto frames = Frames(30, 0.0, 0.0);
  const auto ms = RunSyntheticVo(o, frames, 1);
  ASSERT_FALSE(ms.empty());
  EXPECT_EQ(ms.front().from_stamp, frames[15].capture);
  EXPECT_EQ(ms.front().to_stamp, frames[16].capture);
}

TEST(SyntheticVoTest, DeliveriesStayInCaptureOrderWithinTheLatencyBounds) {
  SyntheticVoOptions o = NoDelay();
  o.latency_jitter_sigma_s = 0.2;  // wide, so clamping and ordering both matter
  const auto ms = RunSyntheticVo(o, Frames(2000, 0.01, 0.0), 7);
  ASSERT_EQ(ms.size(), 1999u);
  double sum = 0.0;
  int at_min = 0, at_max = 0;
  for (std::size_t i = 0; i < ms.size(); ++i) {
    const double latency = (ms[i].stamp - ms[i].to_stamp).ToSeconds();
    EXPECT_GE(latency, o.latency_min_s - 1e-9);
    EXPECT_LE(latency, o.latency_max_s + 1e-9);
    sum += latency;
    at_min += latency < o.latency_min_s + 1e-6;
    at_max += latency > o.latency_max_s - 1e-6;
    if (i > 0) {
      EXPECT_GE(ms[i].stamp, ms[i - 1].stamp);
      EXPECT_GT(ms[i].to_stamp, ms[i - 1].to_stamp);
    }
  }
  EXPECT_GT(at_min, 0);
  EXPECT_GT(at_max, 0);
  // Default jitter: the mean latency is the base.
  const auto nominal = RunSyntheticVo(NoDelay(), Frames(2000, 0.01, 0.0), 7);
  double mean = 0.0;
  for (const auto& m : nominal) mean += (m.stamp - m.to_stamp).ToSeconds();
  mean /= static_cast<double>(nominal.size());
  EXPECT_NEAR(mean, 0.15, 0.005);
}

TEST(SyntheticVoTest, DropsFramesWithTheGivenProbability) {
  SyntheticVoOptions o = NoDelay();
  o.drop_probability = 0.3;
  SyntheticVoStats stats;
  const auto frames = Frames(3000, 0.01, 0.0);
  const auto ms = RunSyntheticVo(o, frames, 3, &stats);
  EXPECT_EQ(stats.frames, 3000u);
  EXPECT_EQ(stats.measurements + stats.dropped + 1, stats.frames);
  EXPECT_NEAR(static_cast<double>(stats.dropped) / 3000.0, 0.3, 0.03);
  // Keyframe counting skips dropped frames: never more than 10 processed
  // frames from one keyframe.
  std::map<Time, int> per_keyframe;
  for (const auto& m : ms) ++per_keyframe[m.from_stamp];
  int full = 0;
  for (const auto& [stamp, n] : per_keyframe) {
    EXPECT_LE(n, 10);
    full += n == 10;
  }
  EXPECT_GT(full, 10);  // 0.01 m per frame: most keyframes end by the frame count
}

// Noise drawn exactly from the stated covariance: the squared Mahalanobis
// distance averages the 6 degrees of freedom.
void ExpectConsistentNoise(const VoNoiseModel& noise, double step_m, double step_rad) {
  SyntheticVoOptions o = NoDelay();
  o.noise = noise;
  const auto frames = Frames(4001, step_m, step_rad);
  const auto ms = RunSyntheticVo(o, frames, 11);
  ASSERT_EQ(ms.size(), 4000u);
  double sum_d2 = 0.0;
  Eigen::Matrix<double, 6, 1> sum_sq_normalised = Eigen::Matrix<double, 6, 1>::Zero();
  std::size_t k = 0;
  Eigen::Isometry3d T_kf = frames[0].T_world_body;
  for (std::size_t i = 0; i < ms.size(); ++i) {
    const Eigen::Isometry3d T_true = T_kf.inverse() * frames[i + 1].T_world_body;
    Eigen::Matrix<double, 6, 1> n;
    n.head<3>() = ms[i].p_from_to - T_true.translation();
    n.tail<3>() =
        LogSO3(Eigen::Matrix3d(T_true.linear().transpose() * ms[i].q_from_to.toRotationMatrix()));
    sum_d2 += n.dot(ms[i].covariance.ldlt().solve(n));
    sum_sq_normalised += n.cwiseQuotient(ms[i].covariance.diagonal().cwiseSqrt()).cwiseAbs2();
    if (ms[i].to_is_keyframe) T_kf = frames[i + 1].T_world_body;
    ++k;
  }
  const double n_draws = static_cast<double>(k);
  // Mean of chi2(6) over 4000 draws: std 0.055.
  EXPECT_NEAR(sum_d2 / n_draws, 6.0, 0.3);
  for (int i = 0; i < 6; ++i) EXPECT_NEAR(sum_sq_normalised(i) / n_draws, 1.0, 0.1) << i;
}

TEST(SyntheticVoTest, NoiseMatchesTheStatedCovarianceIdeal) {
  ExpectConsistentNoise(VoNoiseModel::IdealConsistent(), 0.07, 0.5 * kDeg);
}

TEST(SyntheticVoTest, NoiseMatchesTheStatedCovarianceRealistic) {
  ExpectConsistentNoise(VoNoiseModel::Realistic(), 0.07, 0.5 * kDeg);
}

TEST(SyntheticVoTest, StatedCovarianceFollowsTheModel) {
  const VoNoiseModel m = VoNoiseModel::Realistic();
  const auto c = m.Covariance(Eigen::Vector3d(0.3, 0.4, 0.0), Eigen::Vector3d(0.0, 0.0, 0.1));
  const double st = 0.005 + 0.01 * 0.5;
  const double sr = 0.1 * kDeg + 0.01 * 0.1 + 0.2 * kDeg * 0.5;
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(c(i, i), st * st, 1e-15);
    EXPECT_NEAR(c(i + 3, i + 3), sr * sr, 1e-15);
  }
  EXPECT_EQ((c - Eigen::Matrix<double, 6, 6>(c.diagonal().asDiagonal())).norm(), 0.0);
}

TEST(SyntheticVoTest, SameSeedSameOutputOtherSeedOtherNoise) {
  const auto frames = Frames(100, 0.05, 0.01);
  const auto a = RunSyntheticVo(SyntheticVoOptions{}, frames, 5);
  const auto b = RunSyntheticVo(SyntheticVoOptions{}, frames, 5);
  const auto c = RunSyntheticVo(SyntheticVoOptions{}, frames, 6);
  ASSERT_EQ(a.size(), b.size());
  ASSERT_EQ(a.size(), c.size());
  bool differs = false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].p_from_to, b[i].p_from_to);
    EXPECT_EQ(a[i].q_from_to.coeffs(), b[i].q_from_to.coeffs());
    EXPECT_EQ(a[i].stamp, b[i].stamp);
    differs = differs || a[i].p_from_to != c[i].p_from_to;
  }
  EXPECT_TRUE(differs);
}

TEST(SyntheticVoTest, DisabledGivesNothing) {
  SyntheticVoOptions o;
  o.enabled = false;
  EXPECT_TRUE(RunSyntheticVo(o, Frames(50, 0.05, 0.0), 1).empty());
}

TEST(SyntheticVoTest, LoadsPresetsOverridesAndRejectsBadValues) {
  const ConfigNode node = ConfigNode::LoadString(
      "preset: ideal-consistent\ntrans_base_m: 0.003\nlatency_base_s: 0.2\n", "vo.yaml");
  const SyntheticVoOptions o = SyntheticVoOptions::Load(node);
  node.CheckNoUnknownKeysRecursive();
  EXPECT_EQ(o.noise.trans_base_m, 0.003);
  EXPECT_EQ(o.noise.trans_per_m, VoNoiseModel::IdealConsistent().trans_per_m);
  EXPECT_EQ(o.noise.rot_per_m, 0.0);
  EXPECT_EQ(o.latency_base_s, 0.2);

  EXPECT_THROW(SyntheticVoOptions::Load(ConfigNode::LoadString("preset: perfect\n", "a")),
               ConfigError);
  EXPECT_THROW(SyntheticVoOptions::Load(ConfigNode::LoadString("latency_max_s: 0.6\n", "b")),
               ConfigError);
  EXPECT_THROW(SyntheticVoOptions::Load(ConfigNode::LoadString("latency_base_s: 0.02\n", "c")),
               ConfigError);
  SyntheticVoOptions bad;
  bad.drop_probability = 1.0;
  EXPECT_THROW(bad.Validate(), std::invalid_argument);
  EXPECT_THROW(VoNoiseModel::Preset("nope"), std::invalid_argument);
}

}  // namespace
}  // namespace rover::sim
