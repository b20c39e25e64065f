#ifndef ROVER_ESTIMATOR_EVAL_ATE_H_
#define ROVER_ESTIMATOR_EVAL_ATE_H_

// Absolute trajectory error (ATE) of aligned, associated poses.

#include <vector>

#include "estimator/eval/association.h"
#include "estimator/eval/error_stats.h"

namespace rover::eval {

struct AteResult {
  /// |p_truth - p_estimate| per pose [m].
  std::vector<double> position_errors_m;
  /// Angle of R_estimate^T * R_truth per pose [deg].
  std::vector<double> rotation_errors_deg;
  ErrorStats position_m;
  ErrorStats rotation_deg;
};

/// ATE of `poses`, which should already be aligned (ApplyAlignment()). Empty
/// input gives NaN statistics.
AteResult ComputeAte(const std::vector<AssociatedPose>& poses);

}  // namespace rover::eval

#endif  // ROVER_ESTIMATOR_EVAL_ATE_H_
