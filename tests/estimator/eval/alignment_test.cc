#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <random>

#include "core/geometry/yaw.h"
#include "estimator/eval/alignment.h"
#include "estimator/eval/eval_error.h"
#include "tests/estimator/eval/eval_test_util.h"

namespace rover::eval {
namespace {

// Associated poses whose truth is `truth` and whose estimate is the truth
// seen from another frame: T_est = (T_truth_estimate)^-1 applied with 1/scale.
std::vector<AssociatedPose> Mapped(const Trajectory& truth, const Eigen::Isometry3d& T_truth_est,
                                   double scale) {
  std::vector<AssociatedPose> poses;
  const Eigen::Matrix3d R = T_truth_est.linear();
  for (std::size_t i = 0; i < truth.size(); ++i) {
    AssociatedPose p;
    p.stamp = truth[i].stamp;
    p.T_world_body_truth = truth[i].T_world_body();
    // p_truth = s R p_est + t  =>  p_est = R^T (p_truth - t) / s;  R_est = R^T R_truth.
    p.T_world_body_estimate.linear() = R.transpose() * p.T_world_body_truth.linear();
    p.T_world_body_estimate.translation() =
        R.transpose() * (p.T_world_body_truth.translation() - T_truth_est.translation()) / scale;
    poses.push_back(p);
  }
  return poses;
}

double MaxPoseDifference(const std::vector<AssociatedPose>& poses) {
  double worst = 0.0;
  for (const AssociatedPose& p : poses) {
    worst = std::max(
        worst,
        (p.T_world_body_truth.matrix() - p.T_world_body_estimate.matrix()).cwiseAbs().maxCoeff());
  }
  return worst;
}

class AlignmentTest : public ::testing::TestWithParam<int> {
 protected:
  std::mt19937_64 rng_{static_cast<uint64_t>(1000 + GetParam())};
};

TEST_P(AlignmentTest, Se3RecoversARandomRigidTransform) {
  const Trajectory truth = testing::RandomTrajectory(rng_, 300);
  const Eigen::Isometry3d T = testing::RandomPose(rng_, 20.0);
  AlignmentOptions options;
  options.method = AlignmentMethod::kSe3;
  const std::vector<AssociatedPose> poses = Mapped(truth, T, 1.0);
  const Alignment a = ComputeAlignment(poses, options);
  EXPECT_LT((a.T_truth_estimate.matrix() - T.matrix()).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_EQ(a.scale, 1.0);
  EXPECT_EQ(a.poses_used, 300u);
  EXPECT_LT(MaxPoseDifference(ApplyAlignment(a, poses)), 1e-9);
}

TEST_P(AlignmentTest, Sim3RecoversARandomSimilarity) {
  const Trajectory truth = testing::RandomTrajectory(rng_, 300);
  const Eigen::Isometry3d T = testing::RandomPose(rng_, 20.0);
  const double scale = std::uniform_real_distribution<double>(0.2, 5.0)(rng_);
  AlignmentOptions options;
  options.method = AlignmentMethod::kSim3;
  const std::vector<AssociatedPose> poses = Mapped(truth, T, scale);
  const Alignment a = ComputeAlignment(poses, options);
  EXPECT_LT((a.T_truth_estimate.matrix() - T.matrix()).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_NEAR(a.scale, scale, 1e-9);
  EXPECT_LT(MaxPoseDifference(ApplyAlignment(a, poses)), 1e-9);
  // SE(3) cannot explain the scale.
  options.method = AlignmentMethod::kSe3;
  EXPECT_GT(MaxPoseDifference(ApplyAlignment(ComputeAlignment(poses, options), poses)), 1e-3);
}

TEST_P(AlignmentTest, FourDofRecoversYawAndTranslation) {
  const Trajectory truth = testing::RandomTrajectory(rng_, 300);
  const double yaw = std::uniform_real_distribution<double>(-3.1, 3.1)(rng_);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Rz(yaw);
  T.translation() = testing::RandomVector(rng_, 20.0);
  AlignmentOptions options;
  options.method = AlignmentMethod::kFourDof;
  const std::vector<AssociatedPose> poses = Mapped(truth, T, 1.0);
  const Alignment a = ComputeAlignment(poses, options);
  EXPECT_NEAR(YawOf(a.T_truth_estimate.linear()), yaw, 1e-9);
  EXPECT_LT((a.T_truth_estimate.matrix() - T.matrix()).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LT(MaxPoseDifference(ApplyAlignment(a, poses)), 1e-9);
}

INSTANTIATE_TEST_SUITE_P(Seeds, AlignmentTest, ::testing::Range(0, 5));

TEST(AlignmentLimitsTest, FourDofDoesNotTiltAndFirstPosesLimitsTheFit) {
  std::mt19937_64 rng(3);
  const Trajectory truth = testing::RandomTrajectory(rng, 200);
  // A transform with roll: 4-DoF must keep z up and cannot fit it exactly.
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = ExpSO3(Eigen::Vector3d(0.2, 0.0, 0.5));
  std::vector<AssociatedPose> poses = Mapped(truth, T, 1.0);
  AlignmentOptions options;
  options.method = AlignmentMethod::kFourDof;
  const Alignment a = ComputeAlignment(poses, options);
  EXPECT_NEAR(
      (a.T_truth_estimate.linear() * Eigen::Vector3d::UnitZ() - Eigen::Vector3d::UnitZ()).norm(),
      0.0, 1e-15);

  // Corrupt the second half: aligning on the first 100 poses still recovers T.
  for (std::size_t i = 100; i < poses.size(); ++i) {
    poses[i].T_world_body_estimate.translation() += Eigen::Vector3d(5, -3, 1);
  }
  options.method = AlignmentMethod::kSe3;
  options.first_poses = 100;
  Alignment b = ComputeAlignment(poses, options);
  EXPECT_EQ(b.poses_used, 100u);
  EXPECT_LT((b.T_truth_estimate.matrix() - T.matrix()).cwiseAbs().maxCoeff(), 1e-9);
  options.first_poses = 0;
  options.first_duration = Duration::FromSeconds(100 * 0.05 - 0.01);  // samples every 50 ms
  b = ComputeAlignment(poses, options);
  EXPECT_EQ(b.poses_used, 100u);
  options.first_duration = Duration::Zero();
  EXPECT_GT((ComputeAlignment(poses, options).T_truth_estimate.matrix() - T.matrix())
                .cwiseAbs()
                .maxCoeff(),
            1e-3);
}

TEST(AlignmentLimitsTest, TooFewPosesIsAnError) {
  std::mt19937_64 rng(4);
  const Trajectory truth = testing::RandomTrajectory(rng, 2);
  const std::vector<AssociatedPose> poses = Mapped(truth, Eigen::Isometry3d::Identity(), 1.0);
  AlignmentOptions options;
  options.method = AlignmentMethod::kSe3;
  try {
    ComputeAlignment(poses, options);
    FAIL() << "expected an EvalError";
  } catch (const EvalError& e) {
    EXPECT_STREQ(e.what(), "se3 alignment: expected at least 3 associated poses, found 2");
  }
  options.method = AlignmentMethod::kFourDof;
  EXPECT_NO_THROW(ComputeAlignment(poses, options));
  // Two points 2 d apart spread d around their centroid.
  const double d = 0.5 * (truth[1].p_world_body - truth[0].p_world_body).head<2>().norm();
  EXPECT_NEAR(ComputeAlignment(poses, options).spread_m, d, 1e-12);
  options.method = AlignmentMethod::kNone;
  EXPECT_TRUE(
      ComputeAlignment(poses, options).T_truth_estimate.isApprox(Eigen::Isometry3d::Identity()));
}

TEST(AlignmentNamesTest, RoundTrip) {
  for (const AlignmentMethod m : {AlignmentMethod::kNone, AlignmentMethod::kSe3,
                                  AlignmentMethod::kSim3, AlignmentMethod::kFourDof}) {
    EXPECT_EQ(ParseAlignmentMethod(ToString(m)), m);
  }
  EXPECT_EQ(ParseAlignmentMethod("SE3"), std::nullopt);
}

}  // namespace
}  // namespace rover::eval
