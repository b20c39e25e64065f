#ifndef ROVER_MAPPING_GRAPH_POSE_MANIFOLD_H_
#define ROVER_MAPPING_GRAPH_POSE_MANIFOLD_H_

// Ceres manifold for an SE(3) pose stored as 7 doubles
//   x = [t_x, t_y, t_z, q_x, q_y, q_z, q_w]   (Eigen quaternion storage order)
// with the 6-dimensional tangent delta = [dt; dphi] (translation first):
//   Plus(x, delta) = (t + dt, q (x) Exp(dphi))
// i.e. the translation moves additively in the world frame and the rotation
// takes a right (body-side) perturbation, as the EKF attitude error does.
//
// "Lifted" Jacobian convention: PlusJacobian is [I_6; 0] (7x6), and every cost
// function of this folder writes its Jacobian with respect to the tangent
// delta into the first 6 columns of its 7-column ambient Jacobian (the last
// column is zero). Ceres multiplies the two, so the solver sees exactly the
// analytic tangent Jacobian without the 7x6 quaternion chain rule. Use
// Covariance::GetCovarianceBlockInTangentSpace for covariances.

#include <ceres/manifold.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace rover::mapping {

class PoseManifold final : public ceres::Manifold {
 public:
  int AmbientSize() const override { return 7; }
  int TangentSize() const override { return 6; }
  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override;
  bool PlusJacobian(const double* x, double* jacobian) const override;
  bool Minus(const double* y, const double* x, double* y_minus_x) const override;
  bool MinusJacobian(const double* x, double* jacobian) const override;
};

/// Packs T into the 7-double layout above.
void PoseToParameters(const Eigen::Isometry3d& T, double* x);

/// Unpacks the 7-double layout (normalising the quaternion).
Eigen::Isometry3d PoseFromParameters(const double* x);

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_GRAPH_POSE_MANIFOLD_H_
