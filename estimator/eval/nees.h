#ifndef ROVER_ESTIMATOR_EVAL_NEES_H_
#define ROVER_ESTIMATOR_EVAL_NEES_H_

// Normalized estimation error squared (NEES) of estimates that carry a pose
// covariance, with the error convention of trajectory.h:
//   dp     = p_true - p_est                 (world frame, m)
//   dtheta = LogSO3(R_est^T * R_true)       (body side, rad)
//   NEES_position = dp^T P_pp^-1 dp,   NEES_attitude = dtheta^T P_tt^-1 dtheta,
//   NEES_pose     = e^T P^-1 e with e = [dp; dtheta].
// For a consistent filter these are chi-square with 3, 3 and 6 degrees of
// freedom; their averages should be near 3, 3 and 6 (see chi_square.h for
// acceptance bounds).

#include <cstddef>
#include <limits>
#include <vector>

#include "core/geometry/se3.h"
#include "estimator/eval/association.h"

namespace rover::eval {

/// The NEES of one sample.
struct NeesSample {
  Time stamp;
  double position = 0.0;  ///< 3 dof
  double attitude = 0.0;  ///< 3 dof
  double pose = 0.0;      ///< 6 dof
};

struct NeesResult {
  static constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  std::vector<NeesSample> samples;
  std::size_t without_covariance = 0;  ///< Poses skipped: no covariance.
  std::size_t singular = 0;            ///< Poses skipped: covariance not positive definite.
  double mean_position = kNaN;
  double mean_attitude = kNaN;
  double mean_pose = kNaN;
  /// Fraction of samples inside the two-sided 95 % interval of chi-square(3)
  /// ([0.216, 9.348]); about 0.95 for a consistent filter.
  double position_in_95 = kNaN;
  double attitude_in_95 = kNaN;
};

/// The error [dp; dtheta] of an associated pose (see the header comment).
Vector6d PoseError(const AssociatedPose& pose);

/// NEES of every pose that has a covariance. The poses must be in one frame
/// (ApplyAlignment() rotates the covariances along with the poses).
NeesResult ComputeNees(const std::vector<AssociatedPose>& poses);

}  // namespace rover::eval

#endif  // ROVER_ESTIMATOR_EVAL_NEES_H_
