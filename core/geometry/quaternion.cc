#include "core/geometry/quaternion.h"

namespace rover {

Eigen::Quaterniond NormalizePositiveW(const Eigen::Quaterniond& q) {
  const double scale = (q.w() < 0.0 ? -1.0 : 1.0) / q.norm();
  return Eigen::Quaterniond(scale * q.coeffs());
}

Eigen::Quaterniond Boxplus(const Eigen::Quaterniond& q, const Eigen::Vector3d& dtheta_rad) {
  return (q * QuaternionFromRotationVector(dtheta_rad)).normalized();
}

Eigen::Vector3d Boxminus(const Eigen::Quaterniond& q, const Eigen::Quaterniond& q_ref) {
  // The conjugate is the inverse up to a positive scale, which LogSO3 ignores,
  // so slightly non-unit inputs do not bias the result.
  return LogSO3(q_ref.conjugate() * q);
}

}  // namespace rover
