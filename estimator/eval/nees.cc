#include "estimator/eval/nees.h"

#include <Eigen/Cholesky>
#include <cmath>

#include "core/geometry/so3.h"
#include "core/stats/chi_square.h"

namespace rover::eval {
namespace {

// x^T P^-1 x via Cholesky; false if P is not positive definite.
template <int N>
bool Mahalanobis(const Eigen::Matrix<double, N, N>& P, const Eigen::Matrix<double, N, 1>& x,
                 double* out) {
  const Eigen::LLT<Eigen::Matrix<double, N, N>> llt(P);
  if (llt.info() != Eigen::Success) return false;
  *out = x.dot(llt.solve(x));
  return std::isfinite(*out);
}

}  // namespace

Vector6d PoseError(const AssociatedPose& pose) {
  Vector6d e;
  e.head<3>() = pose.T_world_body_truth.translation() - pose.T_world_body_estimate.translation();
  e.tail<3>() = LogSO3(Eigen::Matrix3d(pose.T_world_body_estimate.linear().transpose() *
                                       pose.T_world_body_truth.linear()));
  return e;
}

NeesResult ComputeNees(const std::vector<AssociatedPose>& poses) {
  NeesResult r;
  const double lower = stats::Chi2Quantile(3, 0.025);
  const double upper = stats::Chi2Quantile(3, 0.975);
  double sum_position = 0.0, sum_attitude = 0.0, sum_pose = 0.0;
  std::size_t position_in = 0, attitude_in = 0;
  for (const AssociatedPose& p : poses) {
    if (!p.covariance) {
      ++r.without_covariance;
      continue;
    }
    const Matrix6d& P = *p.covariance;
    const Vector6d e = PoseError(p);
    NeesSample s;
    s.stamp = p.stamp;
    const Eigen::Matrix3d P_pp = P.topLeftCorner<3, 3>();
    const Eigen::Matrix3d P_tt = P.bottomRightCorner<3, 3>();
    const Eigen::Vector3d dp = e.head<3>();
    const Eigen::Vector3d dtheta = e.tail<3>();
    if (!Mahalanobis<3>(P_pp, dp, &s.position) || !Mahalanobis<3>(P_tt, dtheta, &s.attitude) ||
        !Mahalanobis<6>(P, e, &s.pose)) {
      ++r.singular;
      continue;
    }
    sum_position += s.position;
    sum_attitude += s.attitude;
    sum_pose += s.pose;
    position_in += s.position >= lower && s.position <= upper ? 1 : 0;
    attitude_in += s.attitude >= lower && s.attitude <= upper ? 1 : 0;
    r.samples.push_back(s);
  }
  if (!r.samples.empty()) {
    const double n = static_cast<double>(r.samples.size());
    r.mean_position = sum_position / n;
    r.mean_attitude = sum_attitude / n;
    r.mean_pose = sum_pose / n;
    r.position_in_95 = static_cast<double>(position_in) / n;
    r.attitude_in_95 = static_cast<double>(attitude_in) / n;
  }
  return r;
}

}  // namespace rover::eval
