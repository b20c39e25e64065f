#ifndef ROVER_MAPPING_GRAPH_RELATIVE_POSE_3D_COST_H_
#define ROVER_MAPPING_GRAPH_RELATIVE_POSE_3D_COST_H_

// Full-information ("chi2") relative-pose residual between two SE(3) poses,
// in g2o's EDGE_SE3:QUAT error convention, with analytic Jacobians.

#include <ceres/sized_cost_function.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace rover::mapping {

/// Residual r = U * e, with U the upper Cholesky factor of the information
/// (Omega = U^T U, so |r|^2 = e^T Omega e), and the 6-vector error
///   D = Z^-1 * T_w_i^-1 * T_w_j,   e = [t(D); vec(q(D))]   (q(D) with w >= 0)
/// for the measurement Z = T_i_j. Parameters: the poses i and j in the
/// PoseManifold layout (7 doubles each). Jacobians are written in the lifted
/// convention of pose_manifold.h (tangent Jacobian in the first 6 columns).
class RelativePose3dCost final : public ceres::SizedCostFunction<6, 7, 7> {
 public:
  /// `information` must be symmetric positive definite.
  RelativePose3dCost(const Eigen::Isometry3d& T_i_j,
                     const Eigen::Matrix<double, 6, 6>& information);

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

  /// The unweighted 6-vector error e for the poses T_w_i and T_w_j.
  Eigen::Matrix<double, 6, 1> Error(const Eigen::Isometry3d& T_w_i,
                                    const Eigen::Isometry3d& T_w_j) const;

 private:
  Eigen::Vector3d t_ij_;
  Eigen::Quaterniond q_ij_;
  Eigen::Matrix3d R_ij_;
  Eigen::Matrix<double, 6, 6> sqrt_information_;
};

/// Unary prior on one SE(3) pose, same convention with D = Z^-1 * T_w_x,
/// Z = T_w_prior: r = U * [t(D); vec(q(D))].
class PosePrior3dCost final : public ceres::SizedCostFunction<6, 7> {
 public:
  PosePrior3dCost(const Eigen::Isometry3d& T_w_prior,
                  const Eigen::Matrix<double, 6, 6>& information);

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  Eigen::Vector3d t_;
  Eigen::Quaterniond q_;
  Eigen::Matrix3d R_;
  Eigen::Matrix<double, 6, 6> sqrt_information_;
};

/// Upper Cholesky factor U of a symmetric positive-definite matrix, Omega = U^T U.
Eigen::Matrix<double, 6, 6> SqrtInformation(const Eigen::Matrix<double, 6, 6>& information);

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_GRAPH_RELATIVE_POSE_3D_COST_H_
