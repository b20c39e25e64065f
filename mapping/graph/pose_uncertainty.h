#ifndef ROVER_MAPPING_GRAPH_POSE_UNCERTAINTY_H_
#define ROVER_MAPPING_GRAPH_POSE_UNCERTAINTY_H_

// Uncertain relative poses in RoverGraph's covariance convention: a
// measurement T_a_b with covariance over [dp (m, frame a); dtheta (rad,
// right)], i.e. p_true = p + dp and R_true = R Exp(dtheta).

#include <Eigen/Geometry>
#include <utility>

#include "mapping/graph/pose_graph.h"

namespace rover::mapping {

/// T_b_a = T_a_b^-1 with its covariance in the same convention (first
/// order: dp' = -R^T dp - [R^T p]x dtheta, dtheta' = -R dtheta).
std::pair<Eigen::Isometry3d, Matrix6d> InvertUncertainPose(const Eigen::Isometry3d& T_a_b,
                                                           const Matrix6d& covariance);

/// The Jacobian of InvertUncertainPose's error with respect to the
/// measurement's error, d[dp'; dtheta'] / d[dp; dtheta].
Matrix6d InverseJacobian(const Eigen::Isometry3d& T_a_b);

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_GRAPH_POSE_UNCERTAINTY_H_
