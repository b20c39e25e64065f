#include "mapping/graph/pose_uncertainty.h"

#include <gtest/gtest.h>

#include <random>

namespace rover::mapping {
namespace {

using Vector6d = Eigen::Matrix<double, 6, 1>;

// The error of a perturbed pose in the convention: p_true = p + dp,
// R_true = R Exp(dtheta).
Eigen::Isometry3d Perturbed(const Eigen::Isometry3d& T, const Vector6d& e) {
  Eigen::Isometry3d out = T;
  out.translation() += e.head<3>();
  const double angle = e.tail<3>().norm();
  if (angle > 0.0) {
    out.linear() = T.linear() * Eigen::AngleAxisd(angle, e.tail<3>() / angle).toRotationMatrix();
  }
  return out;
}

Vector6d ErrorOf(const Eigen::Isometry3d& T_true, const Eigen::Isometry3d& T) {
  Vector6d e;
  e.head<3>() = T_true.translation() - T.translation();
  const Eigen::AngleAxisd aa(T.linear().transpose() * T_true.linear());
  e.tail<3>() = aa.angle() * aa.axis();
  return e;
}

Eigen::Isometry3d SomePose() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = (Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  T.translation() = Eigen::Vector3d(6.0, -2.5, 0.4);
  return T;
}

TEST(PoseUncertaintyTest, TheJacobianMatchesNumericDifferences) {
  const Eigen::Isometry3d T = SomePose();
  const Matrix6d J = InverseJacobian(T);
  Matrix6d numeric;
  const double h = 1e-6;
  for (int k = 0; k < 6; ++k) {
    Vector6d e = Vector6d::Zero();
    e(k) = h;
    const Vector6d plus = ErrorOf(Perturbed(T, e).inverse(), T.inverse());
    const Vector6d minus = ErrorOf(Perturbed(T, -e).inverse(), T.inverse());
    numeric.col(k) = (plus - minus) / (2.0 * h);
  }
  EXPECT_LT((J - numeric).cwiseAbs().maxCoeff(), 1e-6) << J << "\n\n" << numeric;
}

TEST(PoseUncertaintyTest, TheInvertedCovarianceMatchesSampledInverses) {
  const Eigen::Isometry3d T = SomePose();
  Vector6d sigmas;
  sigmas << 0.05, 0.03, 0.02, 0.004, 0.003, 0.01;
  const Matrix6d covariance = sigmas.array().square().matrix().asDiagonal();
  const auto [T_inv, inverted] = InvertUncertainPose(T, covariance);
  EXPECT_LT((T_inv.matrix() - T.inverse().matrix()).norm(), 1e-12);
  std::mt19937_64 rng(7);
  std::normal_distribution<double> n(0.0, 1.0);
  Matrix6d sampled = Matrix6d::Zero();
  const int samples = 20000;
  for (int s = 0; s < samples; ++s) {
    Vector6d e;
    for (int k = 0; k < 6; ++k) e(k) = sigmas(k) * n(rng);
    const Vector6d inv_e = ErrorOf(Perturbed(T, e).inverse(), T_inv);
    sampled += inv_e * inv_e.transpose();
  }
  sampled /= samples;
  for (int k = 0; k < 6; ++k) {
    EXPECT_NEAR(std::sqrt(inverted(k, k)), std::sqrt(sampled(k, k)),
                0.03 * std::sqrt(sampled(k, k)))
        << "component " << k;
  }
  // Position and rotation errors correlate once inverted (the lever arm).
  const double coupling = inverted.topRightCorner<3, 3>().cwiseAbs().maxCoeff();
  EXPECT_GT(coupling, 1e-5);
}

}  // namespace
}  // namespace rover::mapping
