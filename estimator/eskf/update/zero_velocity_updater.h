#ifndef ROVER_ESTIMATOR_ESKF_UPDATE_ZERO_VELOCITY_UPDATER_H_
#define ROVER_ESTIMATOR_ESKF_UPDATE_ZERO_VELOCITY_UPDATER_H_

// Standstill measurements: zero velocity (h = v, z = 0) and zero angular
// rate (h = b_g, z = mean gyro reading over the detection window, whose noise
// is the white gyro noise averaged over the window). Not gated: the
// standstill detector (wheels and IMU both still) is the test, and a gate
// would lock out exactly the update that repairs an overconfident velocity.

#include "estimator/eskf/eskf_options.h"
#include "estimator/eskf/state/filter_state.h"
#include "estimator/eskf/update/kalman_update.h"

namespace rover::estimator {

class ZeroVelocityUpdater {
 public:
  ZeroVelocityUpdater(const ZuptOptions& options, const ImuNoiseOptions& imu);

  /// Rows 0-2: velocity; rows 3-5: gyro bias from the window-mean rate.
  LinearisedMeasurement<6, 2> Linearise(const FilterState& state,
                                        const Eigen::Vector3d& mean_gyro_rad_s,
                                        int window_samples) const;

  /// Applies the update (never gated).
  UpdateOutcome Update(FilterState& state, const Eigen::Vector3d& mean_gyro_rad_s,
                       int window_samples) const;

 private:
  ZuptOptions options_;
  double gyro_sample_sigma_rad_s_;
  double gate_;  ///< 0: no gate
};

}  // namespace rover::estimator

#endif  // ROVER_ESTIMATOR_ESKF_UPDATE_ZERO_VELOCITY_UPDATER_H_
