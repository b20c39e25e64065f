#include "mapping/loop/rigid_estimation.h"

#include <algorithm>
#include <cmath>

#include <Eigen/SVD>

#include "core/geometry/yaw.h"

namespace rover::mapping {
namespace {

// Mean of a non-empty point set.
Eigen::Vector3d Centroid(const std::vector<Eigen::Vector3d>& points) {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : points) c += p;
  return c / static_cast<double>(points.size());
}

}  // namespace

bool TwoPointYawTransform(const Eigen::Vector3d& a1, const Eigen::Vector3d& a2,
                          const Eigen::Vector3d& b1, const Eigen::Vector3d& b2,
                          double min_separation_m, Eigen::Isometry3d* T_a_b) {
  // Eq. 6.5: the pairs' directions with their vertical part removed define
  // one gravity-aligned frame per submap; eq. 6.6 is the yaw between them.
  const Eigen::Vector2d da = (a2 - a1).head<2>();
  const Eigen::Vector2d db = (b2 - b1).head<2>();
  if (da.norm() < min_separation_m || db.norm() < min_separation_m) return false;
  const double yaw = std::atan2(da.y(), da.x()) - std::atan2(db.y(), db.x());
  const Eigen::Matrix3d R = Rz(yaw);
  // Eq. 6.7: midpoints onto each other.
  T_a_b->setIdentity();
  T_a_b->linear() = R;
  T_a_b->translation() = 0.5 * (a1 + a2) - R * (0.5 * (b1 + b2));
  return true;
}

bool FitYawTransform(const std::vector<Eigen::Vector3d>& a, const std::vector<Eigen::Vector3d>& b,
                     Eigen::Isometry3d* T_a_b) {
  if (a.size() != b.size() || a.size() < 2) return false;
  const Eigen::Vector3d ca = Centroid(a);
  const Eigen::Vector3d cb = Centroid(b);
  // Maximise sum a_i . Rz(yaw) b_i over the centred xy: yaw = atan2(S, C).
  double c = 0.0;
  double s = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const Eigen::Vector2d pa = (a[i] - ca).head<2>();
    const Eigen::Vector2d pb = (b[i] - cb).head<2>();
    c += pa.dot(pb);
    s += pb.x() * pa.y() - pb.y() * pa.x();
  }
  if (std::hypot(c, s) < 1e-9) return false;
  const Eigen::Matrix3d R = Rz(std::atan2(s, c));
  T_a_b->setIdentity();
  T_a_b->linear() = R;
  T_a_b->translation() = ca - R * cb;
  return true;
}

bool FitRigidTransform(const std::vector<Eigen::Vector3d>& a, const std::vector<Eigen::Vector3d>& b,
                       Eigen::Isometry3d* T_a_b) {
  if (a.size() != b.size() || a.size() < 3) return false;
  const Eigen::Vector3d ca = Centroid(a);
  const Eigen::Vector3d cb = Centroid(b);
  Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < a.size(); ++i) H += (b[i] - cb) * (a[i] - ca).transpose();
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(H, Eigen::ComputeFullU | Eigen::ComputeFullV);
  // Collinear points leave the rotation about their line free.
  if (svd.singularValues()(1) < 1e-9 * std::max(1.0, svd.singularValues()(0))) return false;
  Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
  if ((svd.matrixV() * svd.matrixU().transpose()).determinant() < 0.0) D(2, 2) = -1.0;
  const Eigen::Matrix3d R = svd.matrixV() * D * svd.matrixU().transpose();
  T_a_b->setIdentity();
  T_a_b->linear() = R;
  T_a_b->translation() = ca - R * cb;
  return true;
}

double TiltOf(const Eigen::Matrix3d& R) { return std::acos(std::clamp(R(2, 2), -1.0, 1.0)); }

}  // namespace rover::mapping
