#ifndef ROVER_CORE_GEOMETRY_SE3_H_
#define ROVER_CORE_GEOMETRY_SE3_H_

// SE(3) on Eigen::Isometry3d: exponential/logarithm maps, the adjoint and the
// left/right Jacobians, for the pose-graph back end.
//
// Tangent vectors are 6-vectors ordered TRANSLATION FIRST:
//   xi = (rho, phi),  rho = xi.head<3>() [m],  phi = xi.tail<3>() [rad],
// with the hat operator xi^ = [[skew(phi), rho], [0, 0]] and ExpSE3(xi) the
// matrix exponential of xi^. Note that rho is not the translation of
// ExpSE3(xi): the translation is LeftJacobianSO3(phi) * rho.
//
// T_a_b maps points from frame b into frame a (p_a = T_a_b * p_b); see
// core/geometry/README.md.

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace rover {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

/// Exponential map of SE(3) for xi = (rho [m], phi [rad]): rotation
/// ExpSO3(phi) and translation LeftJacobianSO3(phi) * rho.
Eigen::Isometry3d ExpSE3(const Vector6d& xi);

/// Logarithm map of SE(3), the inverse of ExpSE3: returns xi = (rho, phi) with
/// phi = LogSO3(R) (so |phi| <= pi) and rho = LeftJacobianInverseSO3(phi) * t.
/// T.linear() must be a rotation matrix.
Vector6d LogSE3(const Eigen::Isometry3d& T);

/// Adjoint of T_a_b for the (rho, phi) ordering:
///   Ad(T) = [[R, skew(t) * R], [0, R]],
/// which moves a tangent vector from the body (right) side to the reference
/// (left) side: T * ExpSE3(xi) == ExpSE3(Adjoint(T) * xi) * T, i.e.
/// T * ExpSE3(xi) * T^-1 == ExpSE3(Adjoint(T) * xi).
Matrix6d Adjoint(const Eigen::Isometry3d& T);

/// Left Jacobian of SE(3), defined by
///   ExpSE3(xi + d) ~= ExpSE3(LeftJacobianSE3(xi) * d) * ExpSE3(xi)  for small d.
/// Block form [[Jl(phi), Q(rho, phi)], [0, Jl(phi)]] with Jl the SO(3) left
/// Jacobian and Q the closed-form coupling block (Barfoot, "State Estimation
/// for Robotics", eq. 7.86 in the same (rho, phi) ordering).
Matrix6d LeftJacobianSE3(const Vector6d& xi);

/// Inverse of LeftJacobianSE3(xi), in closed form
/// [[Jl^-1, -Jl^-1 Q Jl^-1], [0, Jl^-1]]; linearizes the logarithm:
///   LogSE3(ExpSE3(d) * ExpSE3(xi)) ~= xi + LeftJacobianInverseSE3(xi) * d.
/// Valid for |phi| < 2 pi.
Matrix6d LeftJacobianInverseSE3(const Vector6d& xi);

/// Right Jacobian of SE(3), RightJacobianSE3(xi) == LeftJacobianSE3(-xi):
///   ExpSE3(xi + d) ~= ExpSE3(xi) * ExpSE3(RightJacobianSE3(xi) * d).
Matrix6d RightJacobianSE3(const Vector6d& xi);

/// Inverse of RightJacobianSE3(xi):
///   LogSE3(ExpSE3(xi) * ExpSE3(d)) ~= xi + RightJacobianInverseSE3(xi) * d.
/// This is the Jacobian of a relative-pose residual with respect to a body-side
/// perturbation. Valid for |phi| < 2 pi.
Matrix6d RightJacobianInverseSE3(const Vector6d& xi);

}  // namespace rover

#endif  // ROVER_CORE_GEOMETRY_SE3_H_
