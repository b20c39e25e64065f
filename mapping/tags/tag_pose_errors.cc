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
  // Each solved pose as its error relative to the unperturbed one; the
  // spread is taken about their mean.
  std::vector<TagPoseErrors> offsets{TagPoseErrors::Zero()};
  offsets.reserve(257);
  for (unsigned signs = 0; signs < 256; ++signs) {
    const std::optional<TagPose> p =
        EstimateTagPose(PerturbedCorners(corners_px, delta_px, signs), tag_size_m, camera, &error);
    if (!p) continue;
    const TagPoseErrors offset = TagPoseError(T0, p->best.T_camera_tag);
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
