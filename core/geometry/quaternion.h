#ifndef ROVER_CORE_GEOMETRY_QUATERNION_H_
#define ROVER_CORE_GEOMETRY_QUATERNION_H_

// Unit-quaternion helpers for the error-state EKF, whose attitude error is a
// 3-vector dtheta applied on the body (right) side:
//   q_true = q_est (x) Exp(dtheta),
// with (x) the Hamilton product of Eigen::Quaterniond. The exponential and
// logarithm themselves (QuaternionFromRotationVector, LogSO3) live in so3.h.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "core/geometry/so3.h"

namespace rover {

/// Returns q scaled to unit norm with a non-negative scalar part (q and -q are
/// the same rotation). Use it to get a canonical representative, e.g. before
/// comparing, hashing or logging quaternions. q must be non-zero.
Eigen::Quaterniond NormalizePositiveW(const Eigen::Quaterniond& q);

/// Right perturbation ("boxplus"): q (x) QuaternionFromRotationVector(dtheta_rad),
/// renormalized to unit length so that repeated updates do not drift. The
/// sign of the result follows q (it is not forced to w >= 0), which keeps
/// successive EKF estimates on the same hemisphere.
Eigen::Quaterniond Boxplus(const Eigen::Quaterniond& q, const Eigen::Vector3d& dtheta_rad);

/// Inverse of Boxplus ("boxminus"): the body-side rotation vector from q_ref to
/// q, LogSO3(q_ref^-1 (x) q), with norm in [0, pi], so that
/// Boxplus(q_ref, Boxminus(q, q_ref)) equals q up to sign. Its Jacobians are
/// RightJacobianInverseSO3(r) with respect to a right perturbation of q and
/// -LeftJacobianInverseSO3(r) with respect to a right perturbation of q_ref,
/// r being the returned vector. Inputs need not be exactly unit-norm.
Eigen::Vector3d Boxminus(const Eigen::Quaterniond& q, const Eigen::Quaterniond& q_ref);

}  // namespace rover

#endif  // ROVER_CORE_GEOMETRY_QUATERNION_H_
