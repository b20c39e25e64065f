#include "host/eval/vio_evaluation.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "core/cli/report_format.h"
#include "core/geometry/so3.h"
#include "core/geometry/yaw.h"

namespace rover::host::eval {

using cli::Fixed;
using cli::General;
namespace {

namespace ev = rover::eval;

// Confidence of the NEES bounds.
constexpr double kNeesConfidence = 0.95;

Eigen::Isometry3d MeasuredPose(const estimator::RelativePoseMeasurement& m) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = m.q_from_to.normalized().toRotationMatrix();
  T.translation() = m.p_from_to;
  return T;
}

}  // namespace

bool VoChain::Add(Time capture, const Eigen::Isometry3d& T_odom_body, bool starts_chain) {
  if (!trajectory_.empty()) {
    const ev::PoseSample& last = trajectory_.samples().back();
    if (capture <= last.stamp) return false;
    if (starts_chain) {
      // The new chain's first pose continues from the previous chain's last.
      T_chain_odom_ = last.T_world_body() * T_odom_body.inverse();
      ++restarts_;
    }
  }
  const Eigen::Isometry3d T_chain_body = T_chain_odom_ * T_odom_body;
  ev::PoseSample s;
  s.stamp = capture;
  s.p_world_body = T_chain_body.translation();
  s.q_world_body = Eigen::Quaterniond(T_chain_body.linear()).normalized();
  trajectory_.Append(s);
  return true;
}

DeltaPoseNees ComputeDeltaPoseNees(
    const std::vector<estimator::RelativePoseMeasurement>& measurements,
    const ev::Trajectory& truth, Duration max_gap) {
  DeltaPoseNees r;
  r.measurements = measurements.size();
  // ComputeNees uses the estimate convention dp = p_true - p_est and
  // dtheta = Log(R_est^T R_true), which is exactly -[n_p; n_theta] of the
  // measurement convention (R_meas = R_true Exp(n_theta) gives
  // n_theta = Log(R_true^T R_meas) = -Log(R_meas^T R_true)). The NEES is a
  // quadratic form, so it is the same for both.
  std::vector<ev::AssociatedPose> poses;
  poses.reserve(measurements.size());
  for (std::size_t i = 0; i < measurements.size(); ++i) {
    const estimator::RelativePoseMeasurement& m = measurements[i];
    const std::optional<ev::PoseSample> from = ev::PoseAt(truth, m.from_stamp, max_gap);
    const std::optional<ev::PoseSample> to = ev::PoseAt(truth, m.to_stamp, max_gap);
    if (!from || !to) {
      ++r.without_truth;
      continue;
    }
    ev::AssociatedPose a;
    a.stamp = m.to_stamp;
    a.estimate_index = i;
    a.T_world_body_estimate = MeasuredPose(m);
    a.T_world_body_truth = from->T_world_body().inverse() * to->T_world_body();
    a.covariance = m.covariance;
    poses.push_back(a);
  }
  r.nees = ev::ComputeNees(poses);
  if (!poses.empty()) {
    double sq_p = 0.0, sq_theta = 0.0, trace_p = 0.0, trace_theta = 0.0;
    for (const ev::AssociatedPose& a : poses) {
      const Vector6d e = ev::PoseError(a);
      sq_p += e.head<3>().squaredNorm();
      sq_theta += e.tail<3>().squaredNorm();
      trace_p += a.covariance->topLeftCorner<3, 3>().trace();
      trace_theta += a.covariance->bottomRightCorner<3, 3>().trace();
    }
    const double n = static_cast<double>(poses.size());
    constexpr double kRadToDeg = 180.0 / std::numbers::pi;
    r.rms_translation_error_m = std::sqrt(sq_p / n);
    r.rms_rotation_error_deg = std::sqrt(sq_theta / n) * kRadToDeg;
    r.rms_translation_sigma_m = std::sqrt(trace_p / n);
    r.rms_rotation_sigma_deg = std::sqrt(trace_theta / n) * kRadToDeg;
  }
  const int n = static_cast<int>(r.nees.samples.size());
  if (n > 0) {
    r.bounds_6dof = rover::stats::AverageNeesBounds(6, n, kNeesConfidence);
    r.bounds_3dof = rover::stats::AverageNeesBounds(3, n, kNeesConfidence);
    r.pose_inside =
        r.nees.mean_pose >= r.bounds_6dof.lower && r.nees.mean_pose <= r.bounds_6dof.upper;
  }
  return r;
}

RpeQuote QuoteRpe(const ev::RpeResult& rpe, double distance_m, double preferred_m) {
  RpeQuote q;
  const ev::RpeSegmentResult* s = rpe.Headline(preferred_m);
  if (s == nullptr) {
    q.note = "no RPE: no requested segment length fits in the " + Fixed(distance_m, 3) +
             " m ground-truth path";
    return q;
  }
  q.length_m = s->length_m;
  q.translation_pct = s->translation_pct.mean;
  q.rotation_deg_per_m = s->rotation_deg_per_m.mean;
  q.segments = s->translation_pct.count;
  const std::string length = General(s->length_m) + " m segments";
  if (s->length_m == preferred_m) {
    q.note = "quoted: the " + length;
  } else if (s->length_m < preferred_m) {
    q.note = "quoted: the " + length + ", the longest that fit: the ground-truth path (" +
             Fixed(distance_m, 3) + " m) is too short for " + General(preferred_m) + " m segments";
  } else {
    q.note = "quoted: the " + length + " (no shorter length was requested)";
  }
  return q;
}

ev::Alignment AlignAtPose(const ev::AssociatedPose& pose, ev::AlignmentMethod method) {
  const Eigen::Matrix3d& R_truth = pose.T_world_body_truth.linear();
  const Eigen::Matrix3d& R_estimate = pose.T_world_body_estimate.linear();
  Eigen::Matrix3d R;
  if (method == ev::AlignmentMethod::kFourDof) {
    R = Rz(YawOf(R_truth) - YawOf(R_estimate));
  } else if (method == ev::AlignmentMethod::kSe3) {
    R = R_truth * R_estimate.transpose();
  } else {
    throw std::invalid_argument("AlignAtPose: expected se3 or 4dof, found " +
                                std::string(ev::ToString(method)));
  }
  ev::Alignment a;
  a.method = method;
  a.T_truth_estimate.linear() = R;
  a.T_truth_estimate.translation() =
      pose.T_world_body_truth.translation() - R * pose.T_world_body_estimate.translation();
  a.poses_used = 1;
  return a;
}

StartAlignedErrors EvaluateAlignedAtStart(const std::vector<ev::AssociatedPose>& poses,
                                          ev::AlignmentMethod method) {
  StartAlignedErrors r;
  if (poses.empty()) {
    r.ate = ev::ComputeAte({});
    return r;
  }
  const std::vector<ev::AssociatedPose> aligned =
      ev::ApplyAlignment(AlignAtPose(poses.front(), method), poses);
  r.ate = ev::ComputeAte(aligned);
  r.final_error_m = r.ate.position_errors_m.back();
  return r;
}

}  // namespace rover::host::eval
