#ifndef ROVER_ESTIMATOR_ESKF_UPDATE_WHEEL_ODOMETRY_UPDATER_H_
#define ROVER_ESTIMATOR_ESKF_UPDATE_WHEEL_ODOMETRY_UPDATER_H_

// Wheel odometry of a four-wheel skid-steered rover as a body-velocity
// measurement at the wheel-axle centre c (lever arm l from the IMU):
//   h(x) = R^T v + (w_m - b_g) x l,   rows: forward (x), lateral (y).
//   forward  z = r (w_FL + w_FR + w_RL + w_RR) / 4
//   lateral  z = 0 (non-holonomic constraint, optional)
//   yaw rate z = r (w_R - w_L) / (track * scrub)  vs  e_z^T (w_m - b_g) (optional)
// Linearised: d(R^T v) = R^T dv + [R^T v]x dtheta, d(w x l) = [l]x dbg.
// The forward noise grows with speed (unmodelled slip ratio) and with the
// estimated slip, the disagreement between front and rear wheels of a side.

#include <array>

#include "estimator/eskf/eskf_input.h"
#include "estimator/eskf/eskf_options.h"
#include "estimator/eskf/state/filter_state.h"
#include "estimator/eskf/update/kalman_update.h"

namespace rover::estimator {

/// Wheel readings averaged over one update period.
struct WheelVelocity {
  double forward_m_s = 0.0;
  double slip_m_s = 0.0;  ///< front-rear disagreement, mean of both sides
  double yaw_rate_rad_s = 0.0;
};

class WheelOdometryUpdater {
 public:
  explicit WheelOdometryUpdater(const WheelOdometryOptions& options);

  /// Body velocities from (averaged) wheel rates.
  WheelVelocity FromWheelRates(const std::array<double, 4>& wheel_rate_rad_s) const;

  /// Rows: forward, lateral, yaw rate; unused rows have zero Jacobian and
  /// residual (they do not change the update) and unit noise.
  LinearisedMeasurement<3, 3> Linearise(const FilterState& state, const WheelVelocity& z,
                                        const Eigen::Vector3d& gyro_rad_s) const;

  /// Gates and applies the update; `gyro_rad_s` is the latest raw gyro reading.
  UpdateOutcome Update(FilterState& state, const WheelVelocity& z,
                       const Eigen::Vector3d& gyro_rad_s) const;

  int dof() const { return dof_; }

 private:
  WheelOdometryOptions options_;
  int dof_;
  double gate_;
};

}  // namespace rover::estimator

#endif  // ROVER_ESTIMATOR_ESKF_UPDATE_WHEEL_ODOMETRY_UPDATER_H_
