#ifndef ROVER_ESTIMATOR_EVAL_ERROR_STATS_H_
#define ROVER_ESTIMATOR_EVAL_ERROR_STATS_H_

// Summary statistics of a list of error magnitudes.

#include <cstddef>
#include <limits>
#include <vector>

namespace rover::eval {

/// Statistics of non-negative error values, in the values' unit. Every field
/// is NaN when count == 0.
struct ErrorStats {
  static constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  std::size_t count = 0;
  double rmse = kNaN;  ///< sqrt(mean(e^2))
  double mean = kNaN;
  double median = kNaN;  ///< Mean of the two middle values for an even count.
  double std = kNaN;     ///< Population standard deviation, sqrt(mean((e - mean)^2)).
  double min = kNaN;
  double max = kNaN;
};

/// Computes ErrorStats over `values` (taken by value: it is sorted).
ErrorStats ComputeErrorStats(std::vector<double> values);

}  // namespace rover::eval

#endif  // ROVER_ESTIMATOR_EVAL_ERROR_STATS_H_
