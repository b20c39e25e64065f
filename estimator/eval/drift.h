#ifndef ROVER_ESTIMATOR_EVAL_DRIFT_H_
#define ROVER_ESTIMATOR_EVAL_DRIFT_H_

// Drift figures relative to the distance travelled, as reported for odometry
// and SLAM systems ("1.10 m mean error over 148.7 m", "0.22 % final error").

#include <limits>
#include <vector>

#include "estimator/eval/association.h"

namespace rover::eval {

struct DriftResult {
  static constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  /// Length of the ground-truth path through the associated poses [m].
  double distance_m = 0.0;
  /// Position error of the last associated pose [m], and as % of distance_m.
  double final_error_m = kNaN;
  double final_error_pct = kNaN;
  /// Mean position error over all associated poses [m], and as % of distance_m.
  double mean_error_m = kNaN;
  double mean_error_pct = kNaN;
};

/// Drift of aligned poses. Percentages are NaN when the distance is zero.
DriftResult ComputeDrift(const std::vector<AssociatedPose>& poses);

/// Cumulative ground-truth path length at each pose [m] (0 at the first).
std::vector<double> TravelledDistances(const std::vector<AssociatedPose>& poses);

}  // namespace rover::eval

#endif  // ROVER_ESTIMATOR_EVAL_DRIFT_H_
