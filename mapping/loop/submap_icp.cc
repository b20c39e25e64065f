#include "mapping/loop/submap_icp.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include "core/geometry/so3.h"
#include "core/geometry/yaw.h"
#include "mapping/loop/option_checks.h"

namespace rover::mapping {
namespace {

using loop_internal::CheckPositive;
using loop_internal::CheckRange;

constexpr double kDistanceShrink = 0.7;
// The Cauchy scale starts at this share of the initial correspondence
// distance: residuals across the whole basin still pull.
constexpr double kRobustStartFactor = 0.5;

// Cauchy weight of a squared residual; 1 without a scale.
double Weight(double r_sq, double scale_m) {
  return scale_m > 0.0 ? 1.0 / (1.0 + r_sq / (scale_m * scale_m)) : 1.0;
}

// d q / d delta for the left perturbation: [I, z x q] (4D) or [I, -[q]x].
template <int Dof>
Eigen::Matrix<double, 3, Dof> PointJacobian(const Eigen::Vector3d& q) {
  Eigen::Matrix<double, 3, Dof> J;
  J.template leftCols<3>().setIdentity();
  if constexpr (Dof == 4) {
    J.col(3) << -q.y(), q.x(), 0.0;
  } else {
    J.template rightCols<3>() = -skew(q);
  }
  return J;
}

// T <- Exp(delta) T.
template <int Dof>
void ApplyLeft(const Eigen::Matrix<double, Dof, 1>& delta, Eigen::Isometry3d* T) {
  Eigen::Matrix3d dR;
  if constexpr (Dof == 4) {
    dR = Rz(delta(3));
  } else {
    dR = ExpSO3(delta.template tail<3>());
  }
  const Eigen::Matrix3d R = dR * T->linear();
  const Eigen::Vector3d t = dR * T->translation() + delta.template head<3>();
  T->setIdentity();
  T->linear() = R;
  T->translation() = t;
}

template <int Dof>
SubmapIcpResult Align(const SubmapMatchData& a, const SubmapMatchData& b,
                      const Eigen::Isometry3d& initial, const SubmapIcpOptions& o) {
  using Vec = Eigen::Matrix<double, Dof, 1>;
  using Mat = Eigen::Matrix<double, Dof, Dof>;
  SubmapIcpResult result;
  result.T_a_b = initial;
  const std::vector<Eigen::Vector3f>& source = b.icp_points();
  const std::vector<Eigen::Vector3f>& source_normals = b.icp_normals();
  const double min_normal_dot = std::cos(o.max_normal_angle_deg * M_PI / 180.0);
  const std::vector<Eigen::Vector3f>& target = a.cloud().points();
  const std::vector<Eigen::Vector3f>& target_normals = a.normals();
  if (source.empty() || target.empty()) return result;
  Eigen::AlignedBox3d box;
  for (const Eigen::Vector3f& p : target) box.extend(p.cast<double>());

  double max_distance = o.initial_distance_m;
  Mat H = Mat::Zero();
  Vec g = Vec::Zero();
  double sum_sq = 0.0;
  double plain_sum_sq = 0.0;
  double point_sum_sq = 0.0;
  int residuals = 0;
  int matched = 0;
  int considered = 0;
  // The Cauchy scale anneals with the correspondence distance (see
  // robust_scale_m).
  double robust_c = kRobustStartFactor * o.initial_distance_m;
  for (int it = 0; it < o.max_iterations; ++it) {
    result.iterations = it + 1;
    H.setZero();
    g.setZero();
    sum_sq = 0.0;
    plain_sum_sq = 0.0;
    point_sum_sq = 0.0;
    residuals = 0;
    matched = 0;
    considered = 0;
    const Eigen::Isometry3d T = result.T_a_b;
    const double c = o.robust_scale_m > 0.0 ? std::max(o.robust_scale_m, robust_c) : 0.0;
    const auto reach = static_cast<float>(max_distance);
    for (std::size_t j = 0; j < source.size(); ++j) {
      const Eigen::Vector3d q = T * source[j].cast<double>();
      if (box.exteriorDistance(q) > max_distance) continue;
      ++considered;
      Neighbour n;
      if (!a.cloud().Nearest(q.cast<float>(), reach, &n)) continue;
      if ((T.linear() * source_normals[j].cast<double>())
              .dot(target_normals[n.index].cast<double>()) < min_normal_dot) {
        continue;
      }
      ++matched;
      const Eigen::Vector3d p = target[n.index].cast<double>();
      const Eigen::Matrix<double, 3, Dof> Jq = PointJacobian<Dof>(q);
      point_sum_sq += (q - p).squaredNorm();
      if (o.metric == IcpMetric::kPointToPlane) {
        const Eigen::Vector3d normal = target_normals[n.index].cast<double>();
        const double r = normal.dot(q - p);
        const Eigen::Matrix<double, 1, Dof> J = normal.transpose() * Jq;
        const double w = Weight(r * r, c);
        H.noalias() += w * J.transpose() * J;
        g.noalias() += w * J.transpose() * r;
        sum_sq += w * r * r;
        plain_sum_sq += r * r;
        ++residuals;
      } else {
        const Eigen::Vector3d r = q - p;
        const double w = Weight(r.squaredNorm(), c);
        H.noalias() += w * Jq.transpose() * Jq;
        g.noalias() += w * Jq.transpose() * r;
        sum_sq += w * r.squaredNorm();
        plain_sum_sq += r.squaredNorm();
        residuals += 3;
      }
    }
    if (matched < o.min_correspondences) return result;
    const Eigen::LDLT<Mat> ldlt(H);
    // A flat patch leaves the translation along it free: no unique step.
    const Eigen::SelfAdjointEigenSolver<Mat> eig(H);
    if (ldlt.info() != Eigen::Success ||
        eig.eigenvalues()(0) <= 1e-9 * eig.eigenvalues()(Dof - 1)) {
      return result;
    }
    const Vec delta = -ldlt.solve(g);
    ApplyLeft<Dof>(delta, &result.T_a_b);
    const bool at_final = max_distance <= o.final_distance_m && c <= o.robust_scale_m;
    if (at_final && delta.template head<3>().norm() < o.convergence_m &&
        delta.template tail<Dof - 3>().norm() < o.convergence_rad) {
      result.converged = true;
      break;
    }
    max_distance = std::max(o.final_distance_m, max_distance * kDistanceShrink);
    robust_c *= kDistanceShrink;
  }

  result.ok = true;
  const auto agree = static_cast<float>(o.obstacle_agreement_distance_m);
  for (std::size_t j = 0; j < source.size(); ++j) {
    if (!b.icp_obstacle()[j]) continue;
    Neighbour n;
    if (!a.cloud().Nearest((result.T_a_b * source[j].cast<double>()).cast<float>(), agree, &n)) {
      continue;
    }
    ++result.obstacle_points_near;
    result.obstacle_points_agreeing += a.obstacle()[n.index] != 0;
  }
  result.correspondences = matched;
  result.overlap_points = matched;
  result.source_points = considered;
  // Unweighted: the Cauchy weights would hide a poor fit from the RMSE test.
  result.rmse_m = std::sqrt(plain_sum_sq / matched);
  result.point_rmse_m = std::sqrt(point_sum_sq / std::max(1, matched));
  // s^2 H^-1 over the left perturbation, then to [dp (a); dtheta (right)]:
  // t_true = Exp(dphi) t + dt  =>  dp = dt - [t]x dphi;  dtheta = R^T dphi.
  const double s2 = sum_sq / std::max(1, residuals - Dof);
  Matrix6d left = Matrix6d::Zero();
  const Mat cov = s2 * H.inverse();
  if constexpr (Dof == 4) {
    const int index[4] = {0, 1, 2, 5};
    for (int i = 0; i < 4; ++i) {
      for (int j = 0; j < 4; ++j) left(index[i], index[j]) = cov(i, j);
    }
  } else {
    left = cov;
  }
  Matrix6d J = Matrix6d::Identity();
  J.block<3, 3>(0, 3) = -skew(result.T_a_b.translation());
  J.block<3, 3>(3, 3) = result.T_a_b.linear().transpose();
  result.covariance = J * left * J.transpose();
  return result;
}

}  // namespace

void SubmapIcpOptions::Validate() const {
  constexpr const char* kC = "SubmapIcpOptions";
  CheckRange(kC, "max_iterations", max_iterations, 1, 10000);
  CheckPositive(kC, "initial_distance_m", initial_distance_m);
  CheckPositive(kC, "final_distance_m", final_distance_m);
  if (final_distance_m > initial_distance_m) {
    loop_internal::FailOption(kC, "final_distance_m", "<= initial_distance_m", final_distance_m);
  }
  CheckPositive(kC, "convergence_m", convergence_m);
  CheckPositive(kC, "convergence_rad", convergence_rad);
  CheckRange(kC, "min_correspondences", min_correspondences, 10, 1e9);
  CheckRange(kC, "max_normal_angle_deg", max_normal_angle_deg, 0.0, 180.0);
  CheckRange(kC, "robust_scale_m", robust_scale_m, 0.0, 100.0);
  CheckPositive(kC, "obstacle_agreement_distance_m", obstacle_agreement_distance_m);
}

SubmapIcpResult AlignSubmaps(const SubmapMatchData& a, const SubmapMatchData& b,
                             const Eigen::Isometry3d& initial, bool four_dof,
                             const SubmapIcpOptions& options) {
  options.Validate();
  return four_dof ? Align<4>(a, b, initial, options) : Align<6>(a, b, initial, options);
}

}  // namespace rover::mapping
