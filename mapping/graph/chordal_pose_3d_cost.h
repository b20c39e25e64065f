#ifndef ROVER_MAPPING_GRAPH_CHORDAL_POSE_3D_COST_H_
#define ROVER_MAPPING_GRAPH_CHORDAL_POSE_3D_COST_H_

// The SE-Sync objective term of one 3D edge, as a 12-dimensional residual
// with analytic Jacobians:
//   r = [ sqrt(kappa) * vec(R_j - R_i * R~_ij) ;      (9, column-major vec)
//         sqrt(tau)   * (t_j - t_i - R_i * t~_ij) ]    (3)
// so that |r|^2 is the edge's contribution to F (see se_sync_objective.h).
// Parameters: poses i and j in the PoseManifold layout; Jacobians use the
// lifted convention of pose_manifold.h.

#include <ceres/sized_cost_function.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace rover::mapping {

class ChordalPose3dCost final : public ceres::SizedCostFunction<12, 7, 7> {
 public:
  /// kappa, tau > 0: the isotropic rotation and translation weights.
  ChordalPose3dCost(const Eigen::Isometry3d& T_i_j, double kappa, double tau);

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  Eigen::Matrix3d R_ij_;
  Eigen::Vector3d t_ij_;
  double sqrt_kappa_;
  double sqrt_tau_;
};

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_GRAPH_CHORDAL_POSE_3D_COST_H_
