#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <random>

#include "core/geometry/so3.h"
#include "core/stats/chi_square.h"
#include "estimator/eval/nees.h"
#include "tests/estimator/eval/eval_test_util.h"

namespace rover::eval {
namespace {

enum class Side { kBody, kWorld };

// Estimates with random covariances whose truth is drawn from those
// covariances: p_true = p_est + dp, R_true = R_est Exp(dtheta) (kBody, the
// stated convention) or Exp(dtheta) R_est (kWorld, a wrong convention).
std::vector<AssociatedPose> DrawSamples(std::mt19937_64& rng, int n, Side side) {
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<AssociatedPose> poses;
  for (int i = 0; i < n; ++i) {
    AssociatedPose p;
    p.stamp = Time::FromNanoseconds(i);
    p.T_world_body_estimate = testing::RandomPose(rng, 10.0);
    // Strongly anisotropic attitude uncertainty (yaw well known, roll not), so
    // the side of the perturbation matters.
    Matrix6d P = testing::RandomCovariance(rng, 0.2, 0.05);
    P.bottomRightCorner<3, 3>().diagonal() += Eigen::Vector3d(0.04, 0.0, 0.0);
    p.covariance = P;
    Vector6d z;
    for (int k = 0; k < 6; ++k) z[k] = normal(rng);
    const Vector6d e = Eigen::LLT<Matrix6d>(P).matrixL() * z;
    p.T_world_body_truth.translation() = p.T_world_body_estimate.translation() + e.head<3>();
    const Eigen::Matrix3d R = p.T_world_body_estimate.linear();
    p.T_world_body_truth.linear() =
        side == Side::kBody ? Eigen::Matrix3d(R * ExpSO3(e.tail<3>())) : ExpSO3(e.tail<3>()) * R;
    poses.push_back(p);
  }
  return poses;
}

TEST(NeesTest, SamplesFromTheStatedCovarianceAverageTheDof) {
  std::mt19937_64 rng(2024);
  const int n = 2000;
  const NeesResult r = ComputeNees(DrawSamples(rng, n, Side::kBody));
  ASSERT_EQ(r.samples.size(), static_cast<std::size_t>(n));
  const stats::ChiSquareInterval three = stats::AverageNeesBounds(3, n);
  const stats::ChiSquareInterval six = stats::AverageNeesBounds(6, n);
  EXPECT_GT(r.mean_position, three.lower);
  EXPECT_LT(r.mean_position, three.upper);
  EXPECT_GT(r.mean_attitude, three.lower);
  EXPECT_LT(r.mean_attitude, three.upper);
  EXPECT_GT(r.mean_pose, six.lower);
  EXPECT_LT(r.mean_pose, six.upper);
  EXPECT_NEAR(r.position_in_95, 0.95, 0.02);
  EXPECT_NEAR(r.attitude_in_95, 0.95, 0.02);
}

TEST(NeesTest, AttitudeErrorOnTheWrongSideIsInconsistent) {
  std::mt19937_64 rng(2024);
  const int n = 2000;
  const NeesResult r = ComputeNees(DrawSamples(rng, n, Side::kWorld));
  EXPECT_GT(r.mean_attitude, stats::AverageNeesBounds(3, n).upper);
}

TEST(NeesTest, ErrorConventionAndSkippedSamples) {
  AssociatedPose p;
  p.T_world_body_estimate.linear() = ExpSO3(Eigen::Vector3d(0.1, 0.2, 0.3));
  p.T_world_body_truth.linear() =
      p.T_world_body_estimate.linear() * ExpSO3(Eigen::Vector3d(0.01, 0, 0));
  p.T_world_body_truth.translation() = Eigen::Vector3d(0.5, 0, 0);
  const Vector6d e = PoseError(p);
  EXPECT_NEAR((e.head<3>() - Eigen::Vector3d(0.5, 0, 0)).norm(), 0.0, 1e-15);   // truth - estimate
  EXPECT_NEAR((e.tail<3>() - Eigen::Vector3d(0.01, 0, 0)).norm(), 0.0, 1e-12);  // body side

  std::vector<AssociatedPose> poses(3, p);
  poses[0].covariance = Matrix6d::Identity() * 0.01;
  poses[1].covariance = Matrix6d::Zero();  // singular
  const NeesResult r = ComputeNees(poses);
  EXPECT_EQ(r.samples.size(), 1u);
  EXPECT_EQ(r.singular, 1u);
  EXPECT_EQ(r.without_covariance, 1u);
  EXPECT_NEAR(r.mean_position, 0.25 / 0.01, 1e-9);
  EXPECT_NEAR(r.mean_attitude, 1e-4 / 0.01, 1e-9);
}

}  // namespace
}  // namespace rover::eval
