#include "mapping/depth/stereo_error_model.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace rover::mapping {

StereoErrorModel::StereoErrorModel(const RectifiedStereo& stereo, double pixel_error_px)
    : stereo_(stereo), pixel_error_px_(pixel_error_px) {
  stereo_.Validate();
  if (!(std::isfinite(pixel_error_px) && pixel_error_px > 0.0)) {
    throw std::invalid_argument("StereoErrorModel.pixel_error_px: expected > 0, found " +
                                std::to_string(pixel_error_px));
  }
}

Eigen::Matrix<double, 3, 4> StereoErrorModel::PointJacobian(const Eigen::Vector3d& p) const {
  // With d = u_l - u_r:  x = b (u_l - cx) / d,  y = b (v - cy) / d,
  // z = f b / d,  v = (v_l + v_r) / 2.  In terms of the point itself,
  // b / d = z / f.
  const double f = stereo_.focal_px;
  const double b = stereo_.baseline_m;
  const double k = p.z() / (f * b);  // 1 / d, metres per ... per pixel of disparity
  Eigen::Matrix<double, 3, 4> J;
  // Columns: u_l, v_l, u_r, v_r.
  J(0, 0) = (b - p.x()) * k;  // b/d - x/d
  J(0, 1) = 0.0;
  J(0, 2) = p.x() * k;
  J(0, 3) = 0.0;
  J(1, 0) = -p.y() * k;
  J(1, 1) = 0.5 * b * k;
  J(1, 2) = p.y() * k;
  J(1, 3) = 0.5 * b * k;
  J(2, 0) = -p.z() * k;
  J(2, 1) = 0.0;
  J(2, 2) = p.z() * k;
  J(2, 3) = 0.0;
  return J;
}

Eigen::Vector3d StereoErrorModel::PointSigma(const Eigen::Vector3d& p) const {
  const Eigen::Matrix<double, 3, 4> J = PointJacobian(p);
  return pixel_error_px_ * J.rowwise().norm();
}

double StereoErrorModel::DistanceSigma(const Eigen::Vector3d& p, const Eigen::Vector3d& q) const {
  const Eigen::Vector3d delta = p - q;
  const double d = delta.norm();
  if (d == 0.0) return 0.0;
  const Eigen::RowVector3d dd_dp = delta.transpose() / d;  // and -dd_dp for q
  const Eigen::RowVector4d gp = dd_dp * PointJacobian(p);
  const Eigen::RowVector4d gq = -dd_dp * PointJacobian(q);
  return pixel_error_px_ * std::sqrt(gp.squaredNorm() + gq.squaredNorm());
}

double StereoErrorModel::HeightDifferenceSigma(const Eigen::Vector3d& p, const Eigen::Vector3d& q,
                                               const Eigen::Vector3d& up_cam) const {
  // d((p - q) . up) / dp = up^T, / dq = -up^T; the two points' image
  // coordinates are independent.
  const Eigen::RowVector4d gp = up_cam.transpose() * PointJacobian(p);
  const Eigen::RowVector4d gq = up_cam.transpose() * PointJacobian(q);
  return pixel_error_px_ * std::sqrt(gp.squaredNorm() + gq.squaredNorm());
}

}  // namespace rover::mapping
