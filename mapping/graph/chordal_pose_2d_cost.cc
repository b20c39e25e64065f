#include "mapping/graph/chordal_pose_2d_cost.h"

#include <cmath>

namespace rover::mapping {

ChordalPose2dCost::ChordalPose2dCost(const Eigen::Vector3d& measurement, double kappa, double tau)
    : t_ij_(measurement.head<2>()),
      theta_ij_(measurement(2)),
      sqrt_2kappa_(std::sqrt(2.0 * kappa)),
      sqrt_tau_(std::sqrt(tau)) {}

bool ChordalPose2dCost::Evaluate(double const* const* parameters, double* residuals,
                                 double** jacobians) const {
  const double thi = parameters[0][2];
  const double thj = parameters[1][2];
  const double ci = std::cos(thi);
  const double si = std::sin(thi);
  const double cj = std::cos(thj);
  const double sj = std::sin(thj);
  const double ca = std::cos(thi + theta_ij_);
  const double sa = std::sin(thi + theta_ij_);
  const Eigen::Vector2d Ri_t(ci * t_ij_.x() - si * t_ij_.y(), si * t_ij_.x() + ci * t_ij_.y());
  residuals[0] = sqrt_2kappa_ * (cj - ca);
  residuals[1] = sqrt_2kappa_ * (sj - sa);
  residuals[2] = sqrt_tau_ * (parameters[1][0] - parameters[0][0] - Ri_t.x());
  residuals[3] = sqrt_tau_ * (parameters[1][1] - parameters[0][1] - Ri_t.y());
  if (jacobians == nullptr) return true;
  using RowJacobian = Eigen::Matrix<double, 4, 3, Eigen::RowMajor>;
  if (jacobians[0] != nullptr) {
    Eigen::Map<RowJacobian> J(jacobians[0]);
    J.setZero();
    J(0, 2) = sqrt_2kappa_ * sa;
    J(1, 2) = -sqrt_2kappa_ * ca;
    J(2, 0) = -sqrt_tau_;
    J(3, 1) = -sqrt_tau_;
    // d(R_i t~)/d theta_i = [-sin, -cos; cos, -sin] t~ = [-(R_i t~).y; (R_i t~).x].
    J(2, 2) = sqrt_tau_ * Ri_t.y();
    J(3, 2) = -sqrt_tau_ * Ri_t.x();
  }
  if (jacobians[1] != nullptr) {
    Eigen::Map<RowJacobian> J(jacobians[1]);
    J.setZero();
    J(0, 2) = -sqrt_2kappa_ * sj;
    J(1, 2) = sqrt_2kappa_ * cj;
    J(2, 0) = sqrt_tau_;
    J(3, 1) = sqrt_tau_;
  }
  return true;
}

}  // namespace rover::mapping
