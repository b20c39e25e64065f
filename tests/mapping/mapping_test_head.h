#ifndef ROVER_TESTS_MAPPING_MAPPING_TEST_HEAD_H_
#define ROVER_TESTS_MAPPING_MAPPING_TEST_HEAD_H_

// The stereo head the mapping tests look through: the simulator's 752x480
// head (f = 460 px, b = 0.11 m), optionally scaled down, posed in a
// gravity frame (z up) with OpenCV camera axes.

#include <cmath>

#include <Eigen/Geometry>

#include "mapping/depth/rectified_stereo.h"

namespace rover::mapping::testing {

/// The simulator's head scaled down by `factor` (4: 188x120).
inline RectifiedStereo SimulatorHead(int factor = 1) {
  RectifiedStereo s;
  s.width_px = 752 / factor;
  s.height_px = 480 / factor;
  s.focal_px = 460.0 / factor;
  s.cx_px = s.width_px / 2.0;
  s.cy_px = s.height_px / 2.0;
  s.baseline_m = 0.11;
  return s;
}

/// Camera at (x, y, height), heading `yaw_rad` from +x, pitched down by
/// `pitch_deg`.
inline Eigen::Isometry3d CameraPose(double x_m, double y_m, double height_m, double yaw_rad,
                                    double pitch_deg) {
  Eigen::Matrix3d R0;
  R0 << 0, 0, 1,  //
      -1, 0, 0,   //
      0, -1, 0;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()) *
               Eigen::AngleAxisd(pitch_deg * M_PI / 180.0, Eigen::Vector3d::UnitY()) * R0;
  T.translation() = Eigen::Vector3d(x_m, y_m, height_m);
  return T;
}

}  // namespace rover::mapping::testing

#endif  // ROVER_TESTS_MAPPING_MAPPING_TEST_HEAD_H_
