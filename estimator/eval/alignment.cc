#include "estimator/eval/alignment.h"

#include <Eigen/SVD>
#include <array>
#include <cmath>
#include <string>

#include "core/geometry/yaw.h"
#include "estimator/eval/eval_error.h"

namespace rover::eval {
namespace {

constexpr std::array<std::pair<AlignmentMethod, std::string_view>, 4> kNames = {{
    {AlignmentMethod::kNone, "none"},
    {AlignmentMethod::kSe3, "se3"},
    {AlignmentMethod::kSim3, "sim3"},
    {AlignmentMethod::kFourDof, "4dof"},
}};

void CheckSizes(const std::vector<Eigen::Vector3d>& estimate,
                const std::vector<Eigen::Vector3d>& truth, std::size_t minimum, const char* what) {
  if (estimate.size() != truth.size()) {
    throw EvalError(std::string(what) + " alignment: expected as many truth as estimate points (" +
                    std::to_string(estimate.size()) + "), found " + std::to_string(truth.size()));
  }
  if (estimate.size() < minimum) {
    throw EvalError(std::string(what) + " alignment: expected at least " + std::to_string(minimum) +
                    " associated poses, found " + std::to_string(estimate.size()));
  }
}

Eigen::Vector3d Mean(const std::vector<Eigen::Vector3d>& points) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : points) sum += p;
  return sum / static_cast<double>(points.size());
}

}  // namespace

std::string_view ToString(AlignmentMethod method) {
  for (const auto& [m, name] : kNames) {
    if (m == method) return name;
  }
  return "unknown";
}

std::optional<AlignmentMethod> ParseAlignmentMethod(std::string_view name) {
  for (const auto& [m, n] : kNames) {
    if (n == name) return m;
  }
  return std::nullopt;
}

Eigen::Isometry3d Alignment::Apply(const Eigen::Isometry3d& T_estimate_body) const {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = T_truth_estimate.linear() * T_estimate_body.linear();
  T.translation() = scale * (T_truth_estimate.linear() * T_estimate_body.translation()) +
                    T_truth_estimate.translation();
  return T;
}

Alignment AlignUmeyama(const std::vector<Eigen::Vector3d>& estimate,
                       const std::vector<Eigen::Vector3d>& truth, bool with_scale) {
  CheckSizes(estimate, truth, 3, with_scale ? "sim3" : "se3");
  const Eigen::Vector3d mean_e = Mean(estimate);
  const Eigen::Vector3d mean_t = Mean(truth);
  Eigen::Matrix3d cross = Eigen::Matrix3d::Zero();  // sum (t - mean_t) (e - mean_e)^T
  double variance_e = 0.0;
  for (std::size_t i = 0; i < estimate.size(); ++i) {
    const Eigen::Vector3d e = estimate[i] - mean_e;
    cross += (truth[i] - mean_t) * e.transpose();
    variance_e += e.squaredNorm();
  }
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(cross, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Vector3d signs = Eigen::Vector3d::Ones();
  if (svd.matrixU().determinant() * svd.matrixV().determinant() < 0.0) signs.z() = -1.0;
  const Eigen::Matrix3d R = svd.matrixU() * signs.asDiagonal() * svd.matrixV().transpose();

  Alignment a;
  a.method = with_scale ? AlignmentMethod::kSim3 : AlignmentMethod::kSe3;
  a.scale = with_scale && variance_e > 0.0 ? svd.singularValues().dot(signs) / variance_e : 1.0;
  a.T_truth_estimate.linear() = R;
  a.T_truth_estimate.translation() = mean_t - a.scale * (R * mean_e);
  a.poses_used = estimate.size();
  a.spread_m = std::sqrt(variance_e / static_cast<double>(estimate.size()));
  return a;
}

Alignment AlignFourDof(const std::vector<Eigen::Vector3d>& estimate,
                       const std::vector<Eigen::Vector3d>& truth) {
  CheckSizes(estimate, truth, 2, "4dof");
  const Eigen::Vector3d mean_e = Mean(estimate);
  const Eigen::Vector3d mean_t = Mean(truth);
  double sin_sum = 0.0, cos_sum = 0.0, variance_e = 0.0;
  for (std::size_t i = 0; i < estimate.size(); ++i) {
    const Eigen::Vector3d e = estimate[i] - mean_e;
    const Eigen::Vector3d t = truth[i] - mean_t;
    sin_sum += e.x() * t.y() - e.y() * t.x();
    cos_sum += e.x() * t.x() + e.y() * t.y();
    variance_e += e.head<2>().squaredNorm();
  }
  const double yaw = (sin_sum == 0.0 && cos_sum == 0.0) ? 0.0 : std::atan2(sin_sum, cos_sum);
  Alignment a;
  a.method = AlignmentMethod::kFourDof;
  a.T_truth_estimate.linear() = Rz(yaw);
  a.T_truth_estimate.translation() = mean_t - Rz(yaw) * mean_e;
  a.poses_used = estimate.size();
  a.spread_m = std::sqrt(variance_e / static_cast<double>(estimate.size()));
  return a;
}

Alignment ComputeAlignment(const std::vector<AssociatedPose>& poses,
                           const AlignmentOptions& options) {
  std::vector<Eigen::Vector3d> estimate, truth;
  for (const AssociatedPose& p : poses) {
    if (options.first_poses > 0 && estimate.size() >= options.first_poses) break;
    if (options.first_duration > Duration::Zero() &&
        p.stamp - poses.front().stamp > options.first_duration) {
      break;
    }
    estimate.push_back(p.T_world_body_estimate.translation());
    truth.push_back(p.T_world_body_truth.translation());
  }
  switch (options.method) {
    case AlignmentMethod::kNone: {
      Alignment a;
      a.poses_used = 0;
      return a;
    }
    case AlignmentMethod::kSe3:
      return AlignUmeyama(estimate, truth, /*with_scale=*/false);
    case AlignmentMethod::kSim3:
      return AlignUmeyama(estimate, truth, /*with_scale=*/true);
    case AlignmentMethod::kFourDof:
      return AlignFourDof(estimate, truth);
  }
  throw EvalError("unknown alignment method");
}

std::vector<AssociatedPose> ApplyAlignment(const Alignment& alignment,
                                           std::vector<AssociatedPose> poses) {
  Matrix6d J = Matrix6d::Identity();
  J.topLeftCorner<3, 3>() = alignment.scale * alignment.T_truth_estimate.linear();
  for (AssociatedPose& p : poses) {
    p.T_world_body_estimate = alignment.Apply(p.T_world_body_estimate);
    if (p.covariance) p.covariance = J * *p.covariance * J.transpose();
  }
  return poses;
}

}  // namespace rover::eval
