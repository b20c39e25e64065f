#ifndef ROVER_MAPPING_LOOP_RIGID_ESTIMATION_H_
#define ROVER_MAPPING_LOOP_RIGID_ESTIMATION_H_

// Transforms T_a_b (p_a = T_a_b * p_b) from point pairs, for the matcher's
// RANSAC: the thesis's 4D two-point hypothesis (eq. 6.5-6.7: x, y, z, yaw;
// roll = pitch = 0 by construction), the 6D baseline's three-point
// least-squares fit (SVD, Arun/Umeyama without scale), and the least-squares
// refits of both on all inliers.

#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace rover::mapping {

/// Eq. 6.5-6.7: the yaw that turns the horizontal direction b1 -> b2 into
/// a1 -> a2, and the translation that maps the pairs' midpoints onto each
/// other. False (T untouched) if either pair is shorter than
/// `min_separation_m` in xy (its direction is undefined).
bool TwoPointYawTransform(const Eigen::Vector3d& a1, const Eigen::Vector3d& a2,
                          const Eigen::Vector3d& b1, const Eigen::Vector3d& b2,
                          double min_separation_m, Eigen::Isometry3d* T_a_b);

/// Least squares over x, y, z, yaw (closed form: 2D Procrustes on the
/// centred xy, then the centroid offset). Needs >= 2 pairs not all at one
/// xy; false otherwise.
bool FitYawTransform(const std::vector<Eigen::Vector3d>& a, const std::vector<Eigen::Vector3d>& b,
                     Eigen::Isometry3d* T_a_b);

/// Least squares over the full rotation (SVD of the cross-covariance, with
/// the reflection fix). Needs >= 3 pairs, not collinear; false otherwise.
bool FitRigidTransform(const std::vector<Eigen::Vector3d>& a, const std::vector<Eigen::Vector3d>& b,
                       Eigen::Isometry3d* T_a_b);

/// Roll and pitch of R (R = Rz(yaw) Ry(pitch) Rx(roll)) as the angle
/// between R's z axis and the vertical, in radians.
double TiltOf(const Eigen::Matrix3d& R);

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_LOOP_RIGID_ESTIMATION_H_
