#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "core/geometry/so3.h"
#include "core/geometry/yaw.h"
#include "estimator/eval/ate.h"
#include "estimator/eval/drift.h"
#include "estimator/eval/error_stats.h"
#include "estimator/eval/eval_error.h"
#include "estimator/eval/rpe.h"
#include "estimator/eval/trajectory_evaluation.h"
#include "tests/estimator/eval/eval_test_util.h"

namespace rover::eval {
namespace {

constexpr double kRadToDeg = 180.0 / std::numbers::pi;

std::vector<AssociatedPose> Identical(const Trajectory& t) {
  std::vector<AssociatedPose> poses;
  for (const PoseSample& s : t) {
    AssociatedPose p;
    p.stamp = s.stamp;
    p.T_world_body_truth = p.T_world_body_estimate = s.T_world_body();
    poses.push_back(p);
  }
  return poses;
}

// Ground truth along +x in steps of 0.125 m (exact in binary), identity attitude.
std::vector<AssociatedPose> StraightLine(int n) {
  std::vector<AssociatedPose> poses(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    AssociatedPose& p = poses[static_cast<std::size_t>(i)];
    p.stamp = Time::FromNanoseconds(int64_t{i} * 10'000'000);
    p.T_world_body_truth.translation() = Eigen::Vector3d(0.125 * i, 0, 0);
    p.T_world_body_estimate = p.T_world_body_truth;
  }
  return poses;
}

TEST(ErrorStatsTest, KnownValues) {
  const ErrorStats s = ComputeErrorStats({3.0, 1.0, 4.0, 2.0});
  EXPECT_EQ(s.count, 4u);
  EXPECT_DOUBLE_EQ(s.mean, 2.5);
  EXPECT_DOUBLE_EQ(s.median, 2.5);
  EXPECT_DOUBLE_EQ(s.rmse, std::sqrt(30.0 / 4.0));
  EXPECT_DOUBLE_EQ(s.std, std::sqrt(1.25));
  EXPECT_EQ(s.min, 1.0);
  EXPECT_EQ(s.max, 4.0);
  EXPECT_TRUE(std::isnan(ComputeErrorStats({}).rmse));
}

TEST(AteTest, IdenticalTrajectoriesHaveZeroError) {
  std::mt19937_64 rng(11);
  const AteResult ate = ComputeAte(Identical(testing::RandomTrajectory(rng, 100)));
  EXPECT_EQ(ate.position_m.count, 100u);
  EXPECT_EQ(ate.position_m.max, 0.0);
  EXPECT_LT(ate.rotation_deg.max, 1e-6);
}

TEST(AteTest, KnownOffsetIsTheError) {
  std::mt19937_64 rng(12);
  std::vector<AssociatedPose> poses = Identical(testing::RandomTrajectory(rng, 100));
  const Eigen::Vector3d offset(0.3, -0.4, 1.2);  // |offset| = 1.3
  const Eigen::Matrix3d tilt = ExpSO3(Eigen::Vector3d(0, 0.02, 0));
  for (AssociatedPose& p : poses) {
    p.T_world_body_estimate.translation() += offset;
    p.T_world_body_estimate.linear() = p.T_world_body_estimate.linear() * tilt;
  }
  const AteResult ate = ComputeAte(poses);
  EXPECT_NEAR(ate.position_m.rmse, 1.3, 1e-12);
  EXPECT_NEAR(ate.position_m.mean, 1.3, 1e-12);
  EXPECT_NEAR(ate.position_m.std, 0.0, 1e-12);
  EXPECT_NEAR(ate.rotation_deg.rmse, 0.02 * kRadToDeg, 1e-9);
  const DriftResult drift = ComputeDrift(poses);
  EXPECT_NEAR(drift.final_error_m, 1.3, 1e-12);
  EXPECT_NEAR(drift.mean_error_pct, 100.0 * 1.3 / drift.distance_m, 1e-9);
}

TEST(DriftTest, DistanceAndPercentages) {
  std::vector<AssociatedPose> poses = StraightLine(801);  // 100 m
  poses.back().T_world_body_estimate.translation() += Eigen::Vector3d(0, 0.5, 0);
  const DriftResult d = ComputeDrift(poses);
  EXPECT_EQ(d.distance_m, 100.0);
  EXPECT_EQ(d.final_error_m, 0.5);
  EXPECT_DOUBLE_EQ(d.final_error_pct, 0.5);
  EXPECT_DOUBLE_EQ(d.mean_error_pct, 100.0 * (0.5 / 801.0) / 100.0);
  // No motion: percentages cannot be computed.
  std::vector<AssociatedPose> still(3);
  EXPECT_TRUE(std::isnan(ComputeDrift(still).final_error_pct));
}

TEST(RpeTest, ScaleDriftOfOnePercentGivesOnePercentAtEveryLength) {
  std::vector<AssociatedPose> poses = StraightLine(801);  // 100 m
  for (AssociatedPose& p : poses) p.T_world_body_estimate.translation() *= 1.01;
  const RpeResult rpe = ComputeRpe(poses);
  ASSERT_EQ(rpe.segments.size(), 5u);
  for (const RpeSegmentResult& s : rpe.segments) {
    const double L = s.length_m;
    // Starts i with 0.125 i + L <= 100.
    EXPECT_EQ(s.translation_pct.count, static_cast<std::size_t>((100.0 - L) / 0.125) + 1) << L;
    EXPECT_NEAR(s.translation_pct.mean, 1.0, 1e-9) << L;
    EXPECT_NEAR(s.translation_pct.max, 1.0, 1e-9) << L;
    EXPECT_NEAR(s.rotation_deg_per_m.max, 0.0, 1e-12) << L;
  }
  ASSERT_NE(rpe.Headline(), nullptr);
  EXPECT_EQ(rpe.Headline()->length_m, 10.0);
}

TEST(RpeTest, HeadingDriftPerMetreIsTheRotationError) {
  std::vector<AssociatedPose> poses = StraightLine(401);  // 50 m
  const double drift_rad_per_m = 0.001;
  for (AssociatedPose& p : poses) {
    p.T_world_body_estimate.linear() = Rz(drift_rad_per_m * p.T_world_body_truth.translation().x());
  }
  RpeOptions options;
  options.segment_lengths_m = {2.0, 20.0};
  const RpeResult rpe = ComputeRpe(poses, options);
  for (const RpeSegmentResult& s : rpe.segments) {
    EXPECT_NEAR(s.rotation_deg_per_m.mean, drift_rad_per_m * kRadToDeg, 1e-9) << s.length_m;
    EXPECT_NEAR(s.rotation_deg_per_m.std, 0.0, 1e-9) << s.length_m;
  }
}

TEST(RpeTest, SegmentsLongerThanTheTrajectoryHaveNoResults) {
  const std::vector<AssociatedPose> poses = StraightLine(41);  // 5 m
  const RpeResult rpe = ComputeRpe(poses);
  EXPECT_EQ(rpe.segments[1].translation_pct.count, 1u);  // exactly one 5 m segment
  EXPECT_EQ(rpe.segments[2].translation_pct.count, 0u);
  EXPECT_TRUE(std::isnan(rpe.segments[2].translation_pct.mean));
  ASSERT_NE(rpe.Headline(), nullptr);
  EXPECT_EQ(rpe.Headline()->length_m, 5.0);  // the longest one that fits
  EXPECT_EQ(ComputeRpe(StraightLine(2)).Headline(), nullptr);
  RpeOptions bad;
  bad.segment_lengths_m = {10.0, -1.0};
  EXPECT_THROW(ComputeRpe(poses, bad), EvalError);
}

TEST(EvaluateTrajectoryTest, RecoversAnOffsetTrajectoryAndExplainsNoOverlap) {
  std::mt19937_64 rng(13);
  const Trajectory truth = testing::RandomTrajectory(rng, 400, 10'000'000);
  const Eigen::Isometry3d T_est_truth = testing::RandomPose(rng, 5.0);
  const Trajectory estimate = truth.Transformed(T_est_truth);
  EvaluationOptions options;
  options.alignment.method = AlignmentMethod::kSe3;
  const TrajectoryEvaluation r = EvaluateTrajectory(estimate, truth, options);
  EXPECT_EQ(r.aligned.size(), 400u);
  EXPECT_LT(r.ate.position_m.max, 1e-9);
  EXPECT_FALSE(r.nees.has_value());

  options.association.time_offset = Duration::Seconds(100);
  try {
    EvaluateTrajectory(estimate, truth, options);
    FAIL() << "expected an EvalError";
  } catch (const EvalError& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("no estimate pose could be associated"));
    EXPECT_THAT(e.what(), ::testing::HasSubstr("400 estimates fall outside"));
  }
}

}  // namespace
}  // namespace rover::eval
