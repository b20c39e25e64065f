#ifndef ROVER_MAPPING_TAGS_TAG_POSE_ERRORS_H_
#define ROVER_MAPPING_TAGS_TAG_POSE_ERRORS_H_

// How far a tag pose may be off, per degree of freedom, in the frame the
// graph's detection factors use: translation in the camera frame [m] and
// rotation as a right perturbation of the tag's attitude [rad]
// (T_true = T_est * Exp(dtheta)). Both steps of the thesis's model (6.2.3)
// produce these: the offline table of maximum errors over distance and tilt,
// and the online spread of the pose under corner perturbations.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>

#include "core/calib/stereo_rectifier.h"

namespace rover::mapping {

/// [dx dy dz (camera) ; droll dpitch dyaw (tag, right)].
using TagPoseErrors = Eigen::Matrix<double, 6, 1>;

/// The error of `estimate` against `truth` in that parametrisation.
TagPoseErrors TagPoseError(const Eigen::Isometry3d& estimate, const Eigen::Isometry3d& truth);

/// R_camera_ray: the line-of-sight frame of a tag at `p_camera_tag` (its z
/// along the line of sight, its x in the plane of the camera's x and the
/// line of sight). A tag's position is known far better across the line of
/// sight than along it, whatever the tag's place in the image: the error
/// table and the perturbation spread hold position errors in this frame
/// (the camera frame for a tag on the optical axis, as the table renders
/// them), and the covariance turns them into the camera frame.
Eigen::Matrix3d LineOfSightRotation(const Eigen::Vector3d& p_camera_tag);

/// The covariance over [dt (camera); dtheta (tag)] of standard deviations
/// `sigma` = [across x, across y, along the line of sight (m); droll dpitch
/// dyaw (rad, tag)] for a tag at `p_camera_tag`.
Eigen::Matrix<double, 6, 6> LineOfSightCovariance(const TagPoseErrors& sigma,
                                                  const Eigen::Vector3d& p_camera_tag);

/// Perturbation `signs` (0..255) of the thesis's 2^8: each of the eight
/// corner coordinates (x0 y0 .. x3 y3, bit k for coordinate k) moved by
/// +delta_px where its bit is set, -delta_px where not.
std::array<Eigen::Vector2d, 4> PerturbedCorners(const std::array<Eigen::Vector2d, 4>& corners_px,
                                                double delta_px, unsigned signs);

struct CornerPerturbation {
  /// Largest deviation per degree of freedom from the mean of all solved
  /// poses (the unperturbed one and the 256 perturbed); the position in the
  /// unperturbed pose's line-of-sight frame (LineOfSightRotation).
  TagPoseErrors max_deviation = TagPoseErrors::Zero();
  int solved = 0;  ///< of 257
  /// Perturbed samples whose best pose fell on the other branch of the
  /// planar ambiguity (more than `flip_angle_rad` from the unperturbed one).
  int flipped = 0;
};

/// The thesis's online step: every combination of +-delta_px on the eight
/// corner coordinates (2^8 = 256 samples) through the same PnP as the
/// detection. Flipped samples are counted, and their poses kept in the
/// spread: a pose that flips under calibration-sized noise is unstable.
CornerPerturbation PerturbCorners(const std::array<Eigen::Vector2d, 4>& corners_px,
                                  double tag_size_m, const calib::RectifiedIntrinsics& camera,
                                  double delta_px, double flip_angle_rad = 0.35);

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_TAGS_TAG_POSE_ERRORS_H_
