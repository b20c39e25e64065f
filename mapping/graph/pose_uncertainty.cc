#include "mapping/graph/pose_uncertainty.h"

namespace rover::mapping {
namespace {

Eigen::Matrix3d Skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d s;
  s << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return s;
}

}  // namespace

Matrix6d InverseJacobian(const Eigen::Isometry3d& T_a_b) {
  const Eigen::Matrix3d R = T_a_b.linear();
  const Eigen::Vector3d p = T_a_b.translation();
  Matrix6d J = Matrix6d::Zero();
  J.topLeftCorner<3, 3>() = -R.transpose();
  J.topRightCorner<3, 3>() = -Skew(R.transpose() * p);
  J.bottomRightCorner<3, 3>() = -R;
  return J;
}

std::pair<Eigen::Isometry3d, Matrix6d> InvertUncertainPose(const Eigen::Isometry3d& T_a_b,
                                                           const Matrix6d& covariance) {
  const Matrix6d J = InverseJacobian(T_a_b);
  Matrix6d inverted = J * covariance * J.transpose();
  inverted = 0.5 * (inverted + inverted.transpose()).eval();
  return {T_a_b.inverse(), inverted};
}

}  // namespace rover::mapping
