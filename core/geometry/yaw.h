#ifndef ROVER_CORE_GEOMETRY_YAW_H_
#define ROVER_CORE_GEOMETRY_YAW_H_

// Yaw / roll-pitch split of a rotation R_world_body in a gravity-aligned frame
// (z up). With an IMU, roll and pitch are observable from gravity while
// x, y, z and yaw are not, so frame-of-reference switches (re-localization,
// map merging) are 4-DoF: translation plus a rotation about z.
//
// Definition. Every R with a non-vertical body x axis factors uniquely as
//   R = Rz(yaw) * R_rp,
// where yaw = atan2(R(1,0), R(0,0)) is the heading of the body x axis
// projected into the horizontal plane, and R_rp = Rz(-yaw) * R is the
// "roll-pitch" part: under R_rp the body x axis lies in the x-z half-plane
// with x >= 0, i.e. its horizontal projection points along the frame's +x axis,
// so YawOf(R_rp) == 0. This is the yaw of the intrinsic Z-Y-X (yaw-pitch-roll)
// Euler angles, and R_rp = Ry(pitch) * Rx(roll). It is undefined when the body
// x axis is vertical (pitch = +-90 deg), which a ground rover never reaches.

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace rover {

/// Rotation by yaw_rad about the z axis (counter-clockwise seen from +z).
Eigen::Matrix3d Rz(double yaw_rad);

/// A transform between two gravity-aligned frames (a frame switch, a submap
/// origin): translation p_m, then rotation Rz(yaw_rad).
Eigen::Isometry3d GravityAlignedTransform(const Eigen::Vector3d& p_m, double yaw_rad);

/// Heading of R_world_body in radians, in [-pi, pi]: the angle from the world x
/// axis to the horizontal projection of the body x axis, atan2(R(1,0), R(0,0)).
double YawOf(const Eigen::Matrix3d& R_world_body);

/// The two factors of R_world_body = R_yaw * R_rollpitch (see the header
/// comment for the exact definition).
struct YawRollPitchSplit {
  double yaw_rad = 0.0;
  Eigen::Matrix3d R_yaw = Eigen::Matrix3d::Identity();        ///< Rz(yaw_rad).
  Eigen::Matrix3d R_rollpitch = Eigen::Matrix3d::Identity();  ///< Zero-yaw part.
};

/// Splits R_world_body into Rz(yaw) and a zero-yaw roll-pitch rotation such
/// that R_world_body == R_yaw * R_rollpitch and YawOf(R_rollpitch) == 0.
YawRollPitchSplit SplitYawRollPitch(const Eigen::Matrix3d& R_world_body);

/// Jacobian of YawOf with respect to a right (body-side) perturbation:
///   YawOf(R * ExpSO3(d)) ~= YawOf(R) + YawJacobianRight(R) * d.
/// Its x entry is always 0 (rolling about the body x axis does not move that
/// axis). It grows without bound as the body x axis approaches vertical.
Eigen::RowVector3d YawJacobianRight(const Eigen::Matrix3d& R_world_body);

}  // namespace rover

#endif  // ROVER_CORE_GEOMETRY_YAW_H_
