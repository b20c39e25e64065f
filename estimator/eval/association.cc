#include "estimator/eval/association.h"

#include <algorithm>

#include "core/geometry/quaternion.h"

namespace rover::eval {
namespace {

Duration Abs(Duration d) { return d < Duration::Zero() ? -d : d; }

// Result of locating t in the ground truth.
enum class Lookup { kFound, kOutside, kGap };

Lookup Locate(const Trajectory& trajectory, Time t, Duration max_gap, Duration snap_tolerance,
              PoseSample* out) {
  const std::vector<PoseSample>& s = trajectory.samples();
  if (s.empty()) return Lookup::kOutside;
  // First sample with stamp >= t.
  const auto upper = std::lower_bound(s.begin(), s.end(), t,
                                      [](const PoseSample& p, Time v) { return p.stamp < v; });
  // Snap to the nearest sample within tolerance.
  const PoseSample* nearest = nullptr;
  if (upper != s.end()) nearest = &*upper;
  if (upper != s.begin()) {
    const PoseSample& before = *(upper - 1);
    if (nearest == nullptr || Abs(t - before.stamp) < Abs(nearest->stamp - t)) nearest = &before;
  }
  if (nearest != nullptr && Abs(nearest->stamp - t) <= snap_tolerance) {
    *out = *nearest;
    out->stamp = t;
    return Lookup::kFound;
  }
  if (upper == s.begin() || upper == s.end()) return Lookup::kOutside;
  const PoseSample& a = *(upper - 1);
  const PoseSample& b = *upper;
  if (b.stamp - a.stamp > max_gap) return Lookup::kGap;
  *out = InterpolatePose(a, b, t);
  return Lookup::kFound;
}

}  // namespace

PoseSample InterpolatePose(const PoseSample& a, const PoseSample& b, Time t) {
  const double f = (t - a.stamp) / (b.stamp - a.stamp);
  PoseSample out;
  out.stamp = t;
  out.p_world_body = a.p_world_body + f * (b.p_world_body - a.p_world_body);
  out.q_world_body = Boxplus(a.q_world_body, f * Boxminus(b.q_world_body, a.q_world_body));
  if (a.v_world_body_m_s && b.v_world_body_m_s) {
    out.v_world_body_m_s = *a.v_world_body_m_s + f * (*b.v_world_body_m_s - *a.v_world_body_m_s);
  }
  out.covariance = f < 0.5 ? a.covariance : b.covariance;
  return out;
}

std::optional<PoseSample> PoseAt(const Trajectory& trajectory, Time t, Duration max_gap,
                                 Duration snap_tolerance) {
  PoseSample out;
  if (Locate(trajectory, t, max_gap, snap_tolerance, &out) != Lookup::kFound) return std::nullopt;
  return out;
}

Association Associate(const Trajectory& estimate, const Trajectory& truth,
                      const AssociationOptions& options) {
  Association result;
  result.poses.reserve(estimate.size());
  for (std::size_t i = 0; i < estimate.size(); ++i) {
    const PoseSample& e = estimate[i];
    PoseSample g;
    switch (
        Locate(truth, e.stamp + options.time_offset, options.max_gap, options.snap_tolerance, &g)) {
      case Lookup::kOutside:
        ++result.skipped_outside;
        continue;
      case Lookup::kGap:
        ++result.skipped_gap;
        continue;
      case Lookup::kFound:
        break;
    }
    AssociatedPose p;
    p.stamp = e.stamp;
    p.estimate_index = i;
    p.T_world_body_estimate = e.T_world_body();
    p.T_world_body_truth = g.T_world_body();
    p.covariance = e.covariance;
    result.poses.push_back(p);
  }
  return result;
}

}  // namespace rover::eval
