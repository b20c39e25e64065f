#ifndef ROVER_TESTS_ESTIMATOR_VO_EUROC_VO_UTIL_H_
#define ROVER_TESTS_ESTIMATOR_VO_EUROC_VO_UTIL_H_

// Helpers for the VO tests and benches that read EuRoC-layout data (the
// dataset's cameras are calib::CameraModels already).

#include <Eigen/Geometry>

#include "drivers/replay/euroc_dataset.h"

namespace rover::estimator::vo::testing {

/// T_world_body of a ground-truth state.
inline Eigen::Isometry3d Pose(const drivers::GroundTruthState& g) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = g.q_world_body.toRotationMatrix();
  T.translation() = g.p_world_body;
  return T;
}

}  // namespace rover::estimator::vo::testing

#endif  // ROVER_TESTS_ESTIMATOR_VO_EUROC_VO_UTIL_H_
