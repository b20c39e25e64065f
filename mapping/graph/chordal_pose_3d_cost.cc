#include "mapping/graph/chordal_pose_3d_cost.h"

#include <cmath>

#include "core/geometry/so3.h"

namespace rover::mapping {

ChordalPose3dCost::ChordalPose3dCost(const Eigen::Isometry3d& T_i_j, double kappa, double tau)
    : R_ij_(T_i_j.linear()),
      t_ij_(T_i_j.translation()),
      sqrt_kappa_(std::sqrt(kappa)),
      sqrt_tau_(std::sqrt(tau)) {}

bool ChordalPose3dCost::Evaluate(double const* const* parameters, double* residuals,
                                 double** jacobians) const {
  const Eigen::Map<const Eigen::Vector3d> ti(parameters[0]);
  const Eigen::Map<const Eigen::Vector3d> tj(parameters[1]);
  const Eigen::Matrix3d Ri =
      Eigen::Map<const Eigen::Quaterniond>(parameters[0] + 3).normalized().toRotationMatrix();
  const Eigen::Matrix3d Rj =
      Eigen::Map<const Eigen::Quaterniond>(parameters[1] + 3).normalized().toRotationMatrix();
  const Eigen::Matrix3d RiRij = Ri * R_ij_;
  Eigen::Map<Eigen::Matrix<double, 12, 1>> r(residuals);
  const Eigen::Matrix3d dR = sqrt_kappa_ * (Rj - RiRij);
  r.head<9>() = Eigen::Map<const Eigen::Matrix<double, 9, 1>>(dR.data());
  r.tail<3>() = sqrt_tau_ * (tj - ti - Ri * t_ij_);
  if (jacobians == nullptr) return true;

  using RowJacobian = Eigen::Matrix<double, 12, 7, Eigen::RowMajor>;
  // Right perturbation R <- R * Exp(d): dR = R * [e_k]x for the k-th axis.
  if (jacobians[0] != nullptr) {
    Eigen::Map<RowJacobian> J(jacobians[0]);
    J.setZero();
    J.block<3, 3>(9, 0) = -sqrt_tau_ * Eigen::Matrix3d::Identity();
    for (int k = 0; k < 3; ++k) {
      const Eigen::Matrix3d d = -sqrt_kappa_ * Ri * skew(Eigen::Vector3d::Unit(k)) * R_ij_;
      J.block<9, 1>(0, 3 + k) = Eigen::Map<const Eigen::Matrix<double, 9, 1>>(d.data());
    }
    J.block<3, 3>(9, 3) = sqrt_tau_ * Ri * skew(t_ij_);
  }
  if (jacobians[1] != nullptr) {
    Eigen::Map<RowJacobian> J(jacobians[1]);
    J.setZero();
    J.block<3, 3>(9, 0) = sqrt_tau_ * Eigen::Matrix3d::Identity();
    for (int k = 0; k < 3; ++k) {
      const Eigen::Matrix3d d = sqrt_kappa_ * Rj * skew(Eigen::Vector3d::Unit(k));
      J.block<9, 1>(0, 3 + k) = Eigen::Map<const Eigen::Matrix<double, 9, 1>>(d.data());
    }
  }
  return true;
}

}  // namespace rover::mapping
