#include "estimator/eval/trajectory_evaluation.h"

#include "estimator/eval/eval_error.h"
#include "estimator/eval/number_format.h"

namespace rover::eval {
namespace {

std::string SpanText(const Trajectory& t) {
  if (t.empty()) return "(empty)";
  return "[" + FormatSeconds(t.samples().front().stamp) + ", " +
         FormatSeconds(t.samples().back().stamp) + "] s";
}

}  // namespace

TrajectoryEvaluation EvaluateTrajectory(const Trajectory& estimate, const Trajectory& truth,
                                        const EvaluationOptions& options) {
  TrajectoryEvaluation r;
  r.estimate_poses = estimate.size();
  Association association = Associate(estimate, truth, options.association);
  r.skipped_outside = association.skipped_outside;
  r.skipped_gap = association.skipped_gap;
  if (association.poses.empty()) {
    throw EvalError(
        "no estimate pose could be associated with the ground truth: the estimate spans " +
        SpanText(estimate) + " and the ground truth " + SpanText(truth) + " (time offset " +
        FormatDouble(options.association.time_offset.ToSeconds()) + " s); " +
        std::to_string(association.skipped_outside) + " estimates fall outside it and " +
        std::to_string(association.skipped_gap) + " inside ground-truth gaps longer than " +
        FormatDouble(options.association.max_gap.ToSeconds()) +
        " s (check the time offset and the maximum gap)");
  }
  r.alignment = ComputeAlignment(association.poses, options.alignment);
  r.aligned = ApplyAlignment(r.alignment, std::move(association.poses));
  r.ate = ComputeAte(r.aligned);
  r.rpe = ComputeRpe(r.aligned, options.rpe);
  r.drift = ComputeDrift(r.aligned);
  for (const AssociatedPose& p : r.aligned) {
    if (p.covariance) {
      r.nees = ComputeNees(r.aligned);
      break;
    }
  }
  return r;
}

}  // namespace rover::eval
