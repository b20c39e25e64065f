#ifndef ROVER_ESTIMATOR_EVAL_RPE_H_
#define ROVER_ESTIMATOR_EVAL_RPE_H_

// Relative pose error per segment length, KITTI-style: for every start pose i
// and every length L, the end pose j is the first one whose ground-truth path
// length from i is at least L; the error of that segment is
//   E = (T_est_i^-1 T_est_j)^-1 (T_truth_i^-1 T_truth_j),
// reported as |translation(E)| / L * 100 [%] and angle(E) / L [deg/m].
// Segments running past the end of the trajectory are not counted.

#include <cstddef>
#include <vector>

#include "estimator/eval/association.h"
#include "estimator/eval/error_stats.h"

namespace rover::eval {

struct RpeOptions {
  /// Segment lengths of travelled ground-truth distance [m].
  std::vector<double> segment_lengths_m = {1.0, 5.0, 10.0, 20.0, 50.0};
  /// Take every n-th pose as a segment start (1: every pose).
  std::size_t start_stride = 1;
};

/// Errors of all segments of one length.
struct RpeSegmentResult {
  double length_m = 0.0;
  ErrorStats translation_pct;     ///< |t(E)| / L * 100 [%]
  ErrorStats rotation_deg_per_m;  ///< angle(E) / L [deg/m]
};

struct RpeResult {
  /// One entry per requested length, in the requested order (count 0 when the
  /// trajectory is shorter than the length).
  std::vector<RpeSegmentResult> segments;

  /// The segment to quote as a single figure: `preferred_m` if it has
  /// results, otherwise the longest shorter length with results, otherwise
  /// the shortest longer one; nullptr if no length has results.
  const RpeSegmentResult* Headline(double preferred_m = 10.0) const;
};

/// RPE of associated poses (alignment does not change it, except for scale).
/// Throws EvalError for a non-positive segment length or a zero stride.
RpeResult ComputeRpe(const std::vector<AssociatedPose>& poses, const RpeOptions& options = {});

}  // namespace rover::eval

#endif  // ROVER_ESTIMATOR_EVAL_RPE_H_
