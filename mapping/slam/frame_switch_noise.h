#ifndef ROVER_MAPPING_SLAM_FRAME_SWITCH_NOISE_H_
#define ROVER_MAPPING_SLAM_FRAME_SWITCH_NOISE_H_

// The covariance a frame switch (w factor) gets in the pose graph.
//
// The filter's covariance at a switch says how well the filter knows its pose
// in the old frame if its measurement errors were white. They are not: stereo
// VO carries a small scale error that is the same for every frame pair, and
// the IMU biases drift slowly, so the errors of one submap's drive add up
// coherently. In simulation (`rover-sim map` reports it per mission) a 6.6 m
// switch is off by 0.004 +- 0.004 m along-track (0.015 m before the images
// were flat-fielded) while the filter claims about 0.001 m. A graph that
// trusts those covariances is so stiff that the Cauchy loss discounts true
// loop closures as outliers, and the pairing gate believes revisits cannot
// be missed.
//
// The model keeps the filter's covariance and adds an odometry error that
// grows with the distance d driven in the frame (the norm of the switch's
// translation), along the displacement and across it, and in yaw:
//   C = s^2 C_filter + (k_along d)^2 u u^T + (k_across d)^2 (I - u u^T)
//       + (k_yaw d)^2 on yaw,
// u the unit displacement. The defaults cover the simulated errors; a real
// rover's come from the same report against ground truth (or surveyed tags).

#include <Eigen/Core>

#include "core/config/config.h"

namespace rover::mapping {

struct FrameSwitchNoiseOptions {
  /// Scales the filter's standard deviations (1: as the filter states them).
  double filter_sigma_scale = 1.0;
  /// Odometry error per metre driven in the frame, along the displacement
  /// and across it (both horizontal and vertical), in m per m.
  double along_sigma_per_m = 0.0012;
  double across_sigma_per_m = 0.0006;
  /// Yaw error per metre driven, in rad per m (0.011 deg per m).
  double yaw_sigma_rad_per_m = 2.0e-4;

  /// Throws std::invalid_argument naming the first key that is negative,
  /// not finite, or (filter_sigma_scale) not positive.
  void Validate() const;
  /// Keys: filter_sigma_scale, along_sigma_per_m, across_sigma_per_m,
  /// yaw_sigma_rad_per_m (all optional; the defaults above).
  static FrameSwitchNoiseOptions Load(const ConfigNode& node);
};

/// The graph's 4x4 covariance over [dp (m, old frame); dyaw (rad)] for a
/// switch that moved `p_old_new_m` with the filter's covariance
/// `filter_covariance` (same order).
Eigen::Matrix4d FrameSwitchCovariance(const Eigen::Matrix4d& filter_covariance,
                                      const Eigen::Vector3d& p_old_new_m,
                                      const FrameSwitchNoiseOptions& options);

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_SLAM_FRAME_SWITCH_NOISE_H_
