#ifndef ROVER_TESTS_ESTIMATOR_VO_EUROC_VO_UTIL_H_
#define ROVER_TESTS_ESTIMATOR_VO_EUROC_VO_UTIL_H_

// Conversions between the EuRoC replay driver's types and the VO's, shared by
// the VO tests and benches that read EuRoC-layout data.

#include <Eigen/Geometry>

#include "core/calib/stereo_rectifier.h"
#include "drivers/replay/euroc_dataset.h"

namespace rover::estimator::vo::testing {

/// The VO's camera model of an EuRoC sensor.yaml calibration (T_body_cam = T_BS).
inline calib::CameraModel ToModel(const drivers::CameraCalibration& c) {
  calib::CameraModel m;
  m.width_px = c.width_px;
  m.height_px = c.height_px;
  m.intrinsics = c.intrinsics;
  m.distortion = c.distortion;
  m.T_body_cam = c.T_body_cam;
  return m;
}

/// T_world_body of a ground-truth state.
inline Eigen::Isometry3d Pose(const drivers::GroundTruthState& g) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = g.q_world_body.toRotationMatrix();
  T.translation() = g.p_world_body;
  return T;
}

}  // namespace rover::estimator::vo::testing

#endif  // ROVER_TESTS_ESTIMATOR_VO_EUROC_VO_UTIL_H_
