#include "mapping/graph/relative_pose_3d_cost.h"

#include <Eigen/Cholesky>

#include "core/geometry/so3.h"

namespace rover::mapping {
namespace {

using Matrix6d = Eigen::Matrix<double, 6, 6>;
using RowJacobian = Eigen::Matrix<double, 6, 7, Eigen::RowMajor>;

// d vec(q (x) Exp(d)) / d d at d = 0, and d vec(Exp(a) (x) q) / d a.
Eigen::Matrix3d RightQuatVecJacobian(const Eigen::Quaterniond& q) {
  return 0.5 * (q.w() * Eigen::Matrix3d::Identity() + skew(q.vec()));
}
Eigen::Matrix3d LeftQuatVecJacobian(const Eigen::Quaterniond& q) {
  return 0.5 * (q.w() * Eigen::Matrix3d::Identity() - skew(q.vec()));
}

}  // namespace

Matrix6d SqrtInformation(const Matrix6d& information) {
  const Eigen::LLT<Matrix6d> llt(information);
  return llt.matrixU();
}

RelativePose3dCost::RelativePose3dCost(const Eigen::Isometry3d& T_i_j, const Matrix6d& information)
    : t_ij_(T_i_j.translation()),
      q_ij_(Eigen::Quaterniond(T_i_j.linear()).normalized()),
      R_ij_(q_ij_.toRotationMatrix()),
      sqrt_information_(SqrtInformation(information)) {}

Eigen::Matrix<double, 6, 1> RelativePose3dCost::Error(const Eigen::Isometry3d& T_w_i,
                                                      const Eigen::Isometry3d& T_w_j) const {
  const Eigen::Quaterniond qi(T_w_i.linear());
  const Eigen::Quaterniond qj(T_w_j.linear());
  Eigen::Quaterniond qd = q_ij_.conjugate() * qi.conjugate() * qj;
  if (qd.w() < 0.0) qd.coeffs() = -qd.coeffs();
  Eigen::Matrix<double, 6, 1> e;
  e.head<3>() = R_ij_.transpose() *
                (T_w_i.linear().transpose() * (T_w_j.translation() - T_w_i.translation()) - t_ij_);
  e.tail<3>() = qd.normalized().vec();
  return e;
}

bool RelativePose3dCost::Evaluate(double const* const* parameters, double* residuals,
                                  double** jacobians) const {
  const Eigen::Map<const Eigen::Vector3d> ti(parameters[0]);
  const Eigen::Map<const Eigen::Quaterniond> qi_raw(parameters[0] + 3);
  const Eigen::Map<const Eigen::Vector3d> tj(parameters[1]);
  const Eigen::Map<const Eigen::Quaterniond> qj_raw(parameters[1] + 3);
  const Eigen::Quaterniond qi = qi_raw.normalized();
  const Eigen::Quaterniond qj = qj_raw.normalized();
  const Eigen::Matrix3d RiT = qi.toRotationMatrix().transpose();

  Eigen::Quaterniond qd = q_ij_.conjugate() * qi.conjugate() * qj;
  if (qd.w() < 0.0) qd.coeffs() = -qd.coeffs();
  const Eigen::Vector3d dt_local = RiT * (tj - ti);
  Eigen::Matrix<double, 6, 1> e;
  e.head<3>() = R_ij_.transpose() * (dt_local - t_ij_);
  e.tail<3>() = qd.vec();
  Eigen::Map<Eigen::Matrix<double, 6, 1>>{residuals} = sqrt_information_ * e;

  if (jacobians == nullptr) return true;
  const Eigen::Matrix3d A = R_ij_.transpose() * RiT;
  if (jacobians[0] != nullptr) {
    Eigen::Matrix<double, 6, 6> J;
    J.topLeftCorner<3, 3>() = -A;
    J.topRightCorner<3, 3>() = R_ij_.transpose() * skew(dt_local);
    J.bottomLeftCorner<3, 3>().setZero();
    J.bottomRightCorner<3, 3>() = -LeftQuatVecJacobian(qd) * R_ij_.transpose();
    Eigen::Map<RowJacobian> out(jacobians[0]);
    out.leftCols<6>() = sqrt_information_ * J;
    out.col(6).setZero();
  }
  if (jacobians[1] != nullptr) {
    Eigen::Matrix<double, 6, 6> J;
    J.topLeftCorner<3, 3>() = A;
    J.topRightCorner<3, 3>().setZero();
    J.bottomLeftCorner<3, 3>().setZero();
    J.bottomRightCorner<3, 3>() = RightQuatVecJacobian(qd);
    Eigen::Map<RowJacobian> out(jacobians[1]);
    out.leftCols<6>() = sqrt_information_ * J;
    out.col(6).setZero();
  }
  return true;
}

PosePrior3dCost::PosePrior3dCost(const Eigen::Isometry3d& T_w_prior, const Matrix6d& information)
    : t_(T_w_prior.translation()),
      q_(Eigen::Quaterniond(T_w_prior.linear()).normalized()),
      R_(q_.toRotationMatrix()),
      sqrt_information_(SqrtInformation(information)) {}

bool PosePrior3dCost::Evaluate(double const* const* parameters, double* residuals,
                               double** jacobians) const {
  const Eigen::Map<const Eigen::Vector3d> t(parameters[0]);
  const Eigen::Quaterniond q = Eigen::Map<const Eigen::Quaterniond>(parameters[0] + 3).normalized();
  Eigen::Quaterniond qd = q_.conjugate() * q;
  if (qd.w() < 0.0) qd.coeffs() = -qd.coeffs();
  Eigen::Matrix<double, 6, 1> e;
  e.head<3>() = R_.transpose() * (t - t_);
  e.tail<3>() = qd.vec();
  Eigen::Map<Eigen::Matrix<double, 6, 1>>{residuals} = sqrt_information_ * e;
  if (jacobians != nullptr && jacobians[0] != nullptr) {
    Eigen::Matrix<double, 6, 6> J = Eigen::Matrix<double, 6, 6>::Zero();
    J.topLeftCorner<3, 3>() = R_.transpose();
    J.bottomRightCorner<3, 3>() = RightQuatVecJacobian(qd);
    Eigen::Map<RowJacobian> out(jacobians[0]);
    out.leftCols<6>() = sqrt_information_ * J;
    out.col(6).setZero();
  }
  return true;
}

}  // namespace rover::mapping
