#include "core/geometry/yaw.h"

#include <cmath>

namespace rover {

Eigen::Isometry3d GravityAlignedTransform(const Eigen::Vector3d& p_m, double yaw_rad) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Rz(yaw_rad);
  T.translation() = p_m;
  return T;
}

Eigen::Matrix3d Rz(double yaw_rad) {
  const double c = std::cos(yaw_rad);
  const double s = std::sin(yaw_rad);
  Eigen::Matrix3d R;
  R << c, -s, 0.0,  //
      s, c, 0.0,    //
      0.0, 0.0, 1.0;
  return R;
}

double YawOf(const Eigen::Matrix3d& R_world_body) {
  return std::atan2(R_world_body(1, 0), R_world_body(0, 0));
}

YawRollPitchSplit SplitYawRollPitch(const Eigen::Matrix3d& R_world_body) {
  YawRollPitchSplit split;
  split.yaw_rad = YawOf(R_world_body);
  split.R_yaw = Rz(split.yaw_rad);
  // Rz(yaw)^T == Rz(-yaw); the transpose avoids a second pair of trig calls.
  split.R_rollpitch = split.R_yaw.transpose() * R_world_body;
  return split;
}

Eigen::RowVector3d YawJacobianRight(const Eigen::Matrix3d& R_world_body) {
  // With a = R(1,0), b = R(0,0) (the horizontal part of the body x axis),
  // d yaw = (b da - a db) / (a^2 + b^2). A right perturbation moves the body x
  // axis by R * (d x e_x) = R * (0, d_z, -d_y) = R.col(1) d_z - R.col(2) d_y.
  const Eigen::Matrix3d& R = R_world_body;
  const double a = R(1, 0);
  const double b = R(0, 0);
  const double inv_h2 = 1.0 / (a * a + b * b);
  return Eigen::RowVector3d(0.0, inv_h2 * (a * R(0, 2) - b * R(1, 2)),
                            inv_h2 * (b * R(1, 1) - a * R(0, 1)));
}

}  // namespace rover
