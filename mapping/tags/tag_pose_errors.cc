#include "mapping/tags/tag_pose_errors.h"

#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "core/geometry/so3.h"
#include "mapping/tags/tag_pose.h"

namespace rover::mapping {

TagPoseErrors TagPoseError(const Eigen::Isometry3d& estimate, const Eigen::Isometry3d& truth) {
  TagPoseErrors e;
  e.head<3>() = truth.translation() - estimate.translation();
  e.tail<3>() = LogSO3(estimate.linear().transpose() * truth.linear());
  return e;
}

Eigen::Matrix3d LineOfSightRotation(const Eigen::Vector3d& p_camera_tag) {
  const Eigen::Vector3d z = p_camera_tag.normalized();
  Eigen::Vector3d x = Eigen::Vector3d::UnitX() - z.x() * z;
  // A tag straight to the camera's side (never in its image): any x will do.
  if (x.norm() < 1e-9) x = Eigen::Vector3d::UnitY() - z.y() * z;
  x.normalize();
  Eigen::Matrix3d R;
  R.col(0) = x;
  R.col(1) = z.cross(x);
  R.col(2) = z;
  return R;
}

Eigen::Matrix<double, 6, 6> LineOfSightCovariance(const TagPoseErrors& sigma,
                                                  const Eigen::Vector3d& p_camera_tag) {
  const Eigen::Matrix3d R = LineOfSightRotation(p_camera_tag);
  Eigen::Matrix<double, 6, 6> c = Eigen::Matrix<double, 6, 6>::Zero();
  c.topLeftCorner<3, 3>() =
      R * sigma.head<3>().array().square().matrix().asDiagonal() * R.transpose();
  c.bottomRightCorner<3, 3>() = sigma.tail<3>().array().square().matrix().asDiagonal();
  return c;
}

std::array<Eigen::Vector2d, 4> PerturbedCorners(const std::array<Eigen::Vector2d, 4>& corners_px,
                                                double delta_px, unsigned signs) {
  std::array<Eigen::Vector2d, 4> c = corners_px;
  for (unsigned k = 0; k < 8; ++k) {
    c[k / 2][static_cast<int>(k % 2)] += (signs >> k) & 1u ? delta_px : -delta_px;
  }
  return c;
}

CornerPerturbation PerturbCorners(const std::array<Eigen::Vector2d, 4>& corners_px,
                                  double tag_size_m, const calib::RectifiedIntrinsics& camera,
                                  double delta_px, double flip_angle_rad) {
  CornerPerturbation out;
  std::string error;
  const std::optional<TagPose> base = EstimateTagPose(corners_px, tag_size_m, camera, &error);
  if (!base) return out;
  const Eigen::Isometry3d& T0 = base->best.T_camera_tag;
  const Eigen::Matrix3d R_ray_camera = LineOfSightRotation(T0.translation()).transpose();
  // Each solved pose as its error relative to the unperturbed one; the
  // spread is taken about their mean.
  std::vector<TagPoseErrors> offsets{TagPoseErrors::Zero()};
  offsets.reserve(257);
  for (unsigned signs = 0; signs < 256; ++signs) {
    const std::optional<TagPose> p =
        EstimateTagPose(PerturbedCorners(corners_px, delta_px, signs), tag_size_m, camera, &error);
    if (!p) continue;
    TagPoseErrors offset = TagPoseError(T0, p->best.T_camera_tag);
    offset.head<3>() = R_ray_camera * offset.head<3>();
    if (offset.tail<3>().norm() > flip_angle_rad) ++out.flipped;
    offsets.push_back(offset);
  }
  out.solved = static_cast<int>(offsets.size());
  TagPoseErrors mean = TagPoseErrors::Zero();
  for (const TagPoseErrors& o : offsets) mean += o;
  mean /= static_cast<double>(offsets.size());
  for (const TagPoseErrors& o : offsets) {
    out.max_deviation = out.max_deviation.cwiseMax((o - mean).cwiseAbs());
  }
  return out;
}

}  // namespace rover::mapping
