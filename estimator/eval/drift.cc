#include "estimator/eval/drift.h"

namespace rover::eval {

std::vector<double> TravelledDistances(const std::vector<AssociatedPose>& poses) {
  std::vector<double> d;
  d.reserve(poses.size());
  double total = 0.0;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    if (i > 0) {
      total += (poses[i].T_world_body_truth.translation() -
                poses[i - 1].T_world_body_truth.translation())
                   .norm();
    }
    d.push_back(total);
  }
  return d;
}

DriftResult ComputeDrift(const std::vector<AssociatedPose>& poses) {
  DriftResult r;
  if (poses.empty()) return r;
  r.distance_m = TravelledDistances(poses).back();
  double sum = 0.0;
  for (const AssociatedPose& p : poses) {
    sum += (p.T_world_body_truth.translation() - p.T_world_body_estimate.translation()).norm();
  }
  r.mean_error_m = sum / static_cast<double>(poses.size());
  const AssociatedPose& last = poses.back();
  r.final_error_m =
      (last.T_world_body_truth.translation() - last.T_world_body_estimate.translation()).norm();
  if (r.distance_m > 0.0) {
    r.final_error_pct = 100.0 * r.final_error_m / r.distance_m;
    r.mean_error_pct = 100.0 * r.mean_error_m / r.distance_m;
  }
  return r;
}

}  // namespace rover::eval
