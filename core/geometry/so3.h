#ifndef ROVER_CORE_GEOMETRY_SO3_H_
#define ROVER_CORE_GEOMETRY_SO3_H_

// SO(3) on Eigen doubles: hat/vee, exponential and logarithm maps (rotation
// matrix and unit quaternion forms), and the left/right Jacobians with their
// inverses, for the error-state EKF and the pose-graph back end.
//
// Conventions (see core/geometry/README.md):
//  * R_a_b rotates vectors from frame b into frame a: v_a = R_a_b * v_b.
//  * Rotation vectors phi are axis * angle in radians; Exp(phi) is the rotation
//    by |phi| about phi / |phi| (right-hand rule).
//  * Quaternions are Eigen::Quaterniond: Hamilton product, stored (x, y, z, w),
//    q_a_b.toRotationMatrix() == R_a_b.
//  * "Right" quantities act on the body side: R * Exp(dtheta); "left" ones on
//    the reference side: Exp(dtheta) * R.
//
// Every function is accurate to about machine precision for all angles,
// including angles of 1e-8 rad and below (series expansions are used near
// zero), and LogSO3 stays accurate near pi.

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace rover {

/// Returns the skew-symmetric ("hat") matrix of v, such that
/// skew(v) * w == v.cross(w) for every w.
Eigen::Matrix3d skew(const Eigen::Vector3d& v);

/// Inverse of skew(): returns v such that skew(v) is the antisymmetric part
/// (m - m^T) / 2 of m. For an exactly skew-symmetric m this is the
/// off-diagonal vector; for a slightly perturbed one it is the least-squares
/// estimate.
Eigen::Vector3d vee(const Eigen::Matrix3d& m);

/// Exponential map of SO(3): the rotation by angle |phi_rad| about the axis
/// phi_rad / |phi_rad| (Rodrigues' formula). Any angle is accepted; the result
/// is orthonormal to machine precision.
Eigen::Matrix3d ExpSO3(const Eigen::Vector3d& phi_rad);

/// Logarithm map of SO(3): the rotation vector phi with |phi| in [0, pi] such
/// that ExpSO3(phi) == R. At exactly |phi| = pi both phi and -phi are valid and
/// either may be returned. R must be a rotation matrix (orthonormal up to
/// rounding, det = +1); the computation goes through the quaternion so it is
/// well conditioned both near the identity and near a half turn.
Eigen::Vector3d LogSO3(const Eigen::Matrix3d& R);

/// Logarithm map of SO(3) for a quaternion: the rotation vector phi with
/// |phi| in [0, pi] such that QuaternionFromRotationVector(phi) equals q or -q
/// (both represent the same rotation; the shorter rotation is returned). The
/// result does not depend on the norm of q, so q need not be normalized, but it
/// must be non-zero.
Eigen::Vector3d LogSO3(const Eigen::Quaterniond& q);

/// Exponential map of SO(3) as a unit quaternion:
/// q = [cos(|phi|/2), sin(|phi|/2) * phi / |phi|], i.e. the quaternion of
/// ExpSO3(phi_rad). The returned w is >= 0 for |phi_rad| <= pi.
Eigen::Quaterniond QuaternionFromRotationVector(const Eigen::Vector3d& phi_rad);

/// Right Jacobian Jr(phi) of SO(3), defined by
///   ExpSO3(phi + d) ~= ExpSO3(phi) * ExpSO3(Jr(phi) * d)   for small d
/// (a change of the rotation vector seen as a body-side perturbation):
///   Jr(phi) = I - (1 - cos t) / t^2 * [phi]x + (t - sin t) / t^3 * [phi]x^2,
/// t = |phi|. Jr(phi) = Jl(-phi) = Jl(phi)^T. Singular at t = 2 pi only.
Eigen::Matrix3d RightJacobianSO3(const Eigen::Vector3d& phi_rad);

/// Inverse of RightJacobianSO3(phi), computed in closed form:
///   Jr^-1(phi) = I + [phi]x / 2 + (1/t^2 - (1 + cos t) / (2 t sin t)) [phi]x^2.
/// It linearizes the logarithm: LogSO3(ExpSO3(phi) * ExpSO3(d)) ~= phi + Jr^-1(phi) d.
/// Valid for t < 2 pi, which covers every output of LogSO3.
Eigen::Matrix3d RightJacobianInverseSO3(const Eigen::Vector3d& phi_rad);

/// Left Jacobian Jl(phi) of SO(3), defined by
///   ExpSO3(phi + d) ~= ExpSO3(Jl(phi) * d) * ExpSO3(phi)   for small d:
///   Jl(phi) = I + (1 - cos t) / t^2 * [phi]x + (t - sin t) / t^3 * [phi]x^2.
/// It is also the "V" matrix of the SE(3) exponential (translation part).
Eigen::Matrix3d LeftJacobianSO3(const Eigen::Vector3d& phi_rad);

/// Inverse of LeftJacobianSO3(phi), in closed form:
///   Jl^-1(phi) = I - [phi]x / 2 + (1/t^2 - (1 + cos t) / (2 t sin t)) [phi]x^2,
/// so that LogSO3(ExpSO3(d) * ExpSO3(phi)) ~= phi + Jl^-1(phi) d. Valid for
/// t < 2 pi.
Eigen::Matrix3d LeftJacobianInverseSO3(const Eigen::Vector3d& phi_rad);

}  // namespace rover

#endif  // ROVER_CORE_GEOMETRY_SO3_H_
