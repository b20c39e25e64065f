#include "core/geometry/so3.h"

#include <cmath>

#include "core/geometry/lie_coefficients.h"

namespace rover {

namespace gi = geometry_internal;

Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(),  //
      v.z(), 0.0, -v.x(),   //
      -v.y(), v.x(), 0.0;
  return m;
}

Eigen::Vector3d vee(const Eigen::Matrix3d& m) {
  return 0.5 * Eigen::Vector3d(m(2, 1) - m(1, 2), m(0, 2) - m(2, 0), m(1, 0) - m(0, 1));
}

Eigen::Matrix3d ExpSO3(const Eigen::Vector3d& phi_rad) {
  const double theta = phi_rad.norm();
  const Eigen::Matrix3d K = skew(phi_rad);
  return Eigen::Matrix3d::Identity() + gi::SinOverTheta(theta) * K +
         gi::OneMinusCosOverTheta2(theta) * (K * K);
}

Eigen::Vector3d LogSO3(const Eigen::Matrix3d& R) {
  // Eigen's matrix-to-quaternion conversion picks the numerically dominant
  // component (trace or largest diagonal entry) first, so the axis stays well
  // defined near a half turn, where R - R^T vanishes and the textbook
  // acos/antisymmetric-part formula loses all precision.
  return LogSO3(Eigen::Quaterniond(R));
}

Eigen::Vector3d LogSO3(const Eigen::Quaterniond& q) {
  // q and -q are the same rotation; flipping to w >= 0 selects the angle in
  // [0, pi].
  const double sign = q.w() < 0.0 ? -1.0 : 1.0;
  const double w = sign * q.w();
  const Eigen::Vector3d v = sign * q.vec();
  const double n = v.norm();
  // theta = 2 atan2(n, w) is well conditioned everywhere (unlike acos(w) near
  // w = 1); phi = theta * v / n only needs care as n -> 0, where we use
  // atan(r) / r = 1 - r^2/3 + r^4/5 - ... with r = n / w (w ~ 1 there).
  if (n < 1e-4 * w) {
    const double r2 = (n * n) / (w * w);
    return (2.0 / w) * (1.0 - r2 / 3.0 + r2 * r2 / 5.0) * v;
  }
  return (2.0 * std::atan2(n, w) / n) * v;
}

Eigen::Quaterniond QuaternionFromRotationVector(const Eigen::Vector3d& phi_rad) {
  const double theta = phi_rad.norm();
  const Eigen::Vector3d xyz = gi::SinHalfOverTheta(theta) * phi_rad;
  return Eigen::Quaterniond(std::cos(0.5 * theta), xyz.x(), xyz.y(), xyz.z());
}

Eigen::Matrix3d RightJacobianSO3(const Eigen::Vector3d& phi_rad) {
  const double theta = phi_rad.norm();
  const Eigen::Matrix3d K = skew(phi_rad);
  return Eigen::Matrix3d::Identity() - gi::OneMinusCosOverTheta2(theta) * K +
         gi::ThetaMinusSinOverTheta3(theta) * (K * K);
}

Eigen::Matrix3d RightJacobianInverseSO3(const Eigen::Vector3d& phi_rad) {
  const double theta = phi_rad.norm();
  const Eigen::Matrix3d K = skew(phi_rad);
  return Eigen::Matrix3d::Identity() + 0.5 * K + gi::InverseJacobianCoefficient(theta) * (K * K);
}

Eigen::Matrix3d LeftJacobianSO3(const Eigen::Vector3d& phi_rad) {
  const double theta = phi_rad.norm();
  const Eigen::Matrix3d K = skew(phi_rad);
  return Eigen::Matrix3d::Identity() + gi::OneMinusCosOverTheta2(theta) * K +
         gi::ThetaMinusSinOverTheta3(theta) * (K * K);
}

Eigen::Matrix3d LeftJacobianInverseSO3(const Eigen::Vector3d& phi_rad) {
  const double theta = phi_rad.norm();
  const Eigen::Matrix3d K = skew(phi_rad);
  return Eigen::Matrix3d::Identity() - 0.5 * K + gi::InverseJacobianCoefficient(theta) * (K * K);
}

}  // namespace rover
