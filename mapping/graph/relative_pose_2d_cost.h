#ifndef ROVER_MAPPING_GRAPH_RELATIVE_POSE_2D_COST_H_
#define ROVER_MAPPING_GRAPH_RELATIVE_POSE_2D_COST_H_

// Full-information ("chi2") relative-pose residual between two SE(2) poses,
// in g2o's EDGE_SE2 error convention, with analytic Jacobians. Poses are
// parameter blocks of 3 doubles (x [m], y [m], theta [rad]); theta is not
// wrapped in the parameters, the residual wraps the angle difference.

#include <ceres/sized_cost_function.h>

#include <Eigen/Core>

namespace rover::mapping {

/// r = U * e, Omega = U^T U, with
///   e = [ R~^T (R_i^T (t_j - t_i) - t~) ;  wrap(theta_j - theta_i - theta~) ]
/// for the measurement (t~, theta~) = T_i_j.
class RelativePose2dCost final : public ceres::SizedCostFunction<3, 3, 3> {
 public:
  /// `measurement` = (x, y, theta) of T_i_j; `information` 3x3 SPD over it.
  RelativePose2dCost(const Eigen::Vector3d& measurement, const Eigen::Matrix3d& information);

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  Eigen::Vector2d t_ij_;
  double theta_ij_;
  Eigen::Matrix2d R_ij_;
  Eigen::Matrix3d sqrt_information_;
};

/// Wraps an angle to [-pi, pi).
double WrapAngle(double angle_rad);

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_GRAPH_RELATIVE_POSE_2D_COST_H_
