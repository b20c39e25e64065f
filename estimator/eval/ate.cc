#include "estimator/eval/ate.h"

#include <cmath>
#include <numbers>

#include "core/geometry/so3.h"

namespace rover::eval {

AteResult ComputeAte(const std::vector<AssociatedPose>& poses) {
  AteResult r;
  r.position_errors_m.reserve(poses.size());
  r.rotation_errors_deg.reserve(poses.size());
  for (const AssociatedPose& p : poses) {
    r.position_errors_m.push_back(
        (p.T_world_body_truth.translation() - p.T_world_body_estimate.translation()).norm());
    const Eigen::Matrix3d dR =
        p.T_world_body_estimate.linear().transpose() * p.T_world_body_truth.linear();
    r.rotation_errors_deg.push_back(LogSO3(dR).norm() * 180.0 / std::numbers::pi);
  }
  r.position_m = ComputeErrorStats(r.position_errors_m);
  r.rotation_deg = ComputeErrorStats(r.rotation_errors_deg);
  return r;
}

}  // namespace rover::eval
