#ifndef ROVER_ESTIMATOR_EVAL_TRAJECTORY_EVALUATION_H_
#define ROVER_ESTIMATOR_EVAL_TRAJECTORY_EVALUATION_H_

// The whole evaluation of one estimate against its ground truth:
// associate -> align -> ATE, RPE, drift and (if covariances are present) NEES.
// This is what `rover-eval ate` prints; other tools call it the same way.

#include <optional>
#include <vector>

#include "estimator/eval/alignment.h"
#include "estimator/eval/association.h"
#include "estimator/eval/ate.h"
#include "estimator/eval/drift.h"
#include "estimator/eval/nees.h"
#include "estimator/eval/rpe.h"
#include "estimator/eval/trajectory.h"

namespace rover::eval {

struct EvaluationOptions {
  AssociationOptions association;
  AlignmentOptions alignment;
  RpeOptions rpe;
};

struct TrajectoryEvaluation {
  std::size_t estimate_poses = 0;   ///< Samples in the estimate.
  std::size_t skipped_outside = 0;  ///< Estimates outside the ground-truth span.
  std::size_t skipped_gap = 0;      ///< Estimates inside ground-truth gaps.
  Alignment alignment;
  /// Associated poses with the estimate mapped into the ground-truth frame.
  std::vector<AssociatedPose> aligned;
  AteResult ate;
  RpeResult rpe;
  DriftResult drift;
  /// Present when at least one associated estimate has a covariance.
  std::optional<NeesResult> nees;
};

/// Runs the evaluation. Throws EvalError when no estimate pose can be
/// associated (the message gives both time spans and the skip counts, and
/// points at the time offset and gap options), when there are too few poses
/// for the alignment, or for invalid RPE options.
TrajectoryEvaluation EvaluateTrajectory(const Trajectory& estimate, const Trajectory& truth,
                                        const EvaluationOptions& options = {});

}  // namespace rover::eval

#endif  // ROVER_ESTIMATOR_EVAL_TRAJECTORY_EVALUATION_H_
