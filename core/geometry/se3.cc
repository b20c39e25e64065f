#include "core/geometry/se3.h"

#include "core/geometry/lie_coefficients.h"
#include "core/geometry/so3.h"

namespace rover {
namespace {

namespace gi = geometry_internal;

// The coupling block Q(rho, phi) of the SE(3) left Jacobian. Only the
// coefficients depend on the angle; they come from lie_coefficients.h so that
// small angles (where all three suffer heavy cancellation) use series.
Eigen::Matrix3d SE3QBlock(const Eigen::Vector3d& rho, const Eigen::Vector3d& phi) {
  const double theta = phi.norm();
  const Eigen::Matrix3d P = skew(rho);
  const Eigen::Matrix3d K = skew(phi);
  const Eigen::Matrix3d KP = K * P;
  const Eigen::Matrix3d PK = P * K;
  const Eigen::Matrix3d KPK = KP * K;
  const Eigen::Matrix3d KK = K * K;
  return 0.5 * P + gi::ThetaMinusSinOverTheta3(theta) * (KP + PK + KPK) +
         gi::SE3QCoefficient2(theta) * (K * KP + PK * K - 3.0 * KPK) +
         gi::SE3QCoefficient3(theta) * (KPK * K + KK * PK);
}

// Inverse of the block upper-triangular [[A, B], [0, A]].
Matrix6d InvertBlockTriangular(const Eigen::Matrix3d& A_inv, const Eigen::Matrix3d& B) {
  Matrix6d out = Matrix6d::Zero();
  out.topLeftCorner<3, 3>() = A_inv;
  out.topRightCorner<3, 3>() = -A_inv * B * A_inv;
  out.bottomRightCorner<3, 3>() = A_inv;
  return out;
}

}  // namespace

Eigen::Isometry3d ExpSE3(const Vector6d& xi) {
  const Eigen::Vector3d rho = xi.head<3>();
  const Eigen::Vector3d phi = xi.tail<3>();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = ExpSO3(phi);
  T.translation() = LeftJacobianSO3(phi) * rho;
  return T;
}

Vector6d LogSE3(const Eigen::Isometry3d& T) {
  const Eigen::Vector3d phi = LogSO3(Eigen::Matrix3d(T.linear()));
  Vector6d xi;
  xi.head<3>() = LeftJacobianInverseSO3(phi) * T.translation();
  xi.tail<3>() = phi;
  return xi;
}

Matrix6d Adjoint(const Eigen::Isometry3d& T) {
  const Eigen::Matrix3d R = T.linear();
  Matrix6d ad = Matrix6d::Zero();
  ad.topLeftCorner<3, 3>() = R;
  ad.topRightCorner<3, 3>() = skew(T.translation()) * R;
  ad.bottomRightCorner<3, 3>() = R;
  return ad;
}

Matrix6d LeftJacobianSE3(const Vector6d& xi) {
  const Eigen::Vector3d rho = xi.head<3>();
  const Eigen::Vector3d phi = xi.tail<3>();
  const Eigen::Matrix3d Jl = LeftJacobianSO3(phi);
  Matrix6d J = Matrix6d::Zero();
  J.topLeftCorner<3, 3>() = Jl;
  J.topRightCorner<3, 3>() = SE3QBlock(rho, phi);
  J.bottomRightCorner<3, 3>() = Jl;
  return J;
}

Matrix6d LeftJacobianInverseSE3(const Vector6d& xi) {
  const Eigen::Vector3d rho = xi.head<3>();
  const Eigen::Vector3d phi = xi.tail<3>();
  return InvertBlockTriangular(LeftJacobianInverseSO3(phi), SE3QBlock(rho, phi));
}

Matrix6d RightJacobianSE3(const Vector6d& xi) { return LeftJacobianSE3(-xi); }

Matrix6d RightJacobianInverseSE3(const Vector6d& xi) { return LeftJacobianInverseSE3(-xi); }

}  // namespace rover
