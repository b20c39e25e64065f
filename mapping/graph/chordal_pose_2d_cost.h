#ifndef ROVER_MAPPING_GRAPH_CHORDAL_POSE_2D_COST_H_
#define ROVER_MAPPING_GRAPH_CHORDAL_POSE_2D_COST_H_

// The SE-Sync objective term of one 2D edge as a 4-dimensional residual with
// analytic Jacobians. For 2x2 rotations |R_j - R_i R~|_F^2 equals
// 2 |R_j e_1 - R_i R~ e_1|^2, so
//   r = [ sqrt(2 kappa) * ([cos th_j; sin th_j] - [cos(th_i + th~); sin(th_i + th~)]) ;
//         sqrt(tau) * (t_j - t_i - R_i t~) ]
// and |r|^2 is the edge's contribution to F. Parameters: (x, y, theta) x 2.

#include <ceres/sized_cost_function.h>

#include <Eigen/Core>

namespace rover::mapping {

class ChordalPose2dCost final : public ceres::SizedCostFunction<4, 3, 3> {
 public:
  ChordalPose2dCost(const Eigen::Vector3d& measurement, double kappa, double tau);

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  Eigen::Vector2d t_ij_;
  double theta_ij_;
  double sqrt_2kappa_;
  double sqrt_tau_;
};

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_GRAPH_CHORDAL_POSE_2D_COST_H_
