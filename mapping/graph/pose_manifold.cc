#include "mapping/graph/pose_manifold.h"

#include "core/geometry/so3.h"

namespace rover::mapping {

bool PoseManifold::Plus(const double* x, const double* delta, double* x_plus_delta) const {
  for (int i = 0; i < 3; ++i) x_plus_delta[i] = x[i] + delta[i];
  const Eigen::Map<const Eigen::Quaterniond> q(x + 3);
  const Eigen::Quaterniond dq = QuaternionFromRotationVector(Eigen::Vector3d(delta + 3));
  Eigen::Map<Eigen::Quaterniond> out(x_plus_delta + 3);
  out = (q * dq).normalized();
  return true;
}

bool PoseManifold::PlusJacobian(const double* /*x*/, double* jacobian) const {
  Eigen::Map<Eigen::Matrix<double, 7, 6, Eigen::RowMajor>> J(jacobian);
  J.setZero();
  J.topRows<6>().setIdentity();
  return true;
}

bool PoseManifold::Minus(const double* y, const double* x, double* y_minus_x) const {
  for (int i = 0; i < 3; ++i) y_minus_x[i] = y[i] - x[i];
  const Eigen::Map<const Eigen::Quaterniond> qy(y + 3);
  const Eigen::Map<const Eigen::Quaterniond> qx(x + 3);
  Eigen::Map<Eigen::Vector3d>{y_minus_x + 3} = LogSO3(qx.conjugate() * qy);
  return true;
}

bool PoseManifold::MinusJacobian(const double* /*x*/, double* jacobian) const {
  Eigen::Map<Eigen::Matrix<double, 6, 7, Eigen::RowMajor>> J(jacobian);
  J.setZero();
  J.leftCols<6>().setIdentity();
  return true;
}

void PoseToParameters(const Eigen::Isometry3d& T, double* x) {
  Eigen::Map<Eigen::Vector3d> t(x);
  Eigen::Map<Eigen::Quaterniond> q(x + 3);
  t = T.translation();
  q = Eigen::Quaterniond(T.linear()).normalized();
}

Eigen::Isometry3d PoseFromParameters(const double* x) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(x);
  T.linear() = Eigen::Map<const Eigen::Quaterniond>(x + 3).normalized().toRotationMatrix();
  return T;
}

}  // namespace rover::mapping
