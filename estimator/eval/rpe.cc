#include "estimator/eval/rpe.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/geometry/so3.h"
#include "estimator/eval/drift.h"
#include "estimator/eval/eval_error.h"
#include "estimator/eval/number_format.h"

namespace rover::eval {

const RpeSegmentResult* RpeResult::Headline(double preferred_m) const {
  const RpeSegmentResult* shorter = nullptr;
  const RpeSegmentResult* longer = nullptr;
  for (const RpeSegmentResult& s : segments) {
    if (s.translation_pct.count == 0) continue;
    if (s.length_m == preferred_m) return &s;
    if (s.length_m < preferred_m && (shorter == nullptr || s.length_m > shorter->length_m)) {
      shorter = &s;
    }
    if (s.length_m > preferred_m && (longer == nullptr || s.length_m < longer->length_m)) {
      longer = &s;
    }
  }
  return shorter != nullptr ? shorter : longer;
}

RpeResult ComputeRpe(const std::vector<AssociatedPose>& poses, const RpeOptions& options) {
  if (options.start_stride == 0) throw EvalError("RPE: expected a start stride >= 1, found 0");
  for (const double length : options.segment_lengths_m) {
    if (!(length > 0.0) || !std::isfinite(length)) {
      throw EvalError("RPE: expected positive segment lengths, found " + FormatDouble(length));
    }
  }
  const std::vector<double> distance = TravelledDistances(poses);
  RpeResult result;
  for (const double length : options.segment_lengths_m) {
    std::vector<double> translation, rotation;
    std::size_t end = 0;
    for (std::size_t i = 0; i < poses.size(); i += options.start_stride) {
      // The end index only moves forward as the start does.
      end = std::max(end, i);
      while (end < poses.size() && distance[end] - distance[i] < length) ++end;
      if (end == poses.size()) break;
      const Eigen::Isometry3d truth =
          poses[i].T_world_body_truth.inverse() * poses[end].T_world_body_truth;
      const Eigen::Isometry3d estimate =
          poses[i].T_world_body_estimate.inverse() * poses[end].T_world_body_estimate;
      const Eigen::Isometry3d error = estimate.inverse() * truth;
      translation.push_back(100.0 * error.translation().norm() / length);
      rotation.push_back(LogSO3(Eigen::Matrix3d(error.linear())).norm() * 180.0 / std::numbers::pi /
                         length);
    }
    RpeSegmentResult s;
    s.length_m = length;
    s.translation_pct = ComputeErrorStats(std::move(translation));
    s.rotation_deg_per_m = ComputeErrorStats(std::move(rotation));
    result.segments.push_back(s);
  }
  return result;
}

}  // namespace rover::eval
