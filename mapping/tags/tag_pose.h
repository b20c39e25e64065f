#ifndef ROVER_MAPPING_TAGS_TAG_POSE_H_
#define ROVER_MAPPING_TAGS_TAG_POSE_H_

// The 6D pose of a square tag from its four corners in a rectified image:
// OpenCV's IPPE for squares, which returns both poses that fit four coplanar
// corners. Seen nearly head-on, or small in the image, the two fit almost
// equally well and differ by a tilt of the tag's normal mirrored about the
// line of sight (the "flip" every AprilTag user meets). Both are kept, with
// their reprojection errors, so that the caller can refuse what it cannot
// tell apart instead of taking the wrong one.

#include <Eigen/Geometry>
#include <array>
#include <optional>
#include <string>

#include "core/calib/stereo_rectifier.h"

namespace rover::mapping {

/// One pose that fits the corners.
struct TagPoseSolution {
  Eigen::Isometry3d T_camera_tag = Eigen::Isometry3d::Identity();
  double reprojection_rmse_px = 0.0;
};

struct TagPose {
  TagPoseSolution best;         ///< the smaller reprojection error
  TagPoseSolution alternative;  ///< the other solution of the planar ambiguity
  /// best's over the alternative's reprojection RMSE, in (0, 1]: near 1 the
  /// corners cannot tell the two apart.
  double ambiguity_ratio = 0.0;
  /// Of the best pose: distance from the camera to the tag centre [m], and
  /// tilt Phi [rad], the angle between the tag's normal (towards the camera)
  /// and the line of sight to its centre, signed by the normal's direction
  /// across the line of sight (positive: to the image's right).
  double distance_m = 0.0;
  double tilt_rad = 0.0;
};

/// Tilt Phi of a tag at T_camera_tag, as TagPose::tilt_rad [rad].
double TagTilt(const Eigen::Isometry3d& T_camera_tag);

/// The tag's pose in the camera frame (x right, y down, z forward) from its
/// corners (TagDetection order), its side length [m] (the black square) and
/// the rectified intrinsics. Returns nullopt and sets `error` for a
/// non-positive size, non-finite corners or intrinsics, or a solver failure.
std::optional<TagPose> EstimateTagPose(const std::array<Eigen::Vector2d, 4>& corners_px,
                                       double tag_size_m, const calib::RectifiedIntrinsics& camera,
                                       std::string* error);

/// The corners (TagDetection order) a tag of side `tag_size_m` at
/// T_camera_tag projects to.
std::array<Eigen::Vector2d, 4> ProjectTagCorners(const Eigen::Isometry3d& T_camera_tag,
                                                 double tag_size_m,
                                                 const calib::RectifiedIntrinsics& camera);

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_TAGS_TAG_POSE_H_
