#ifndef ROVER_ESTIMATOR_ESKF_UPDATE_WHEEL_ODOMETRY_UPDATER_H_
#define ROVER_ESTIMATOR_ESKF_UPDATE_WHEEL_ODOMETRY_UPDATER_H_

// Wheel odometry of a four-wheel skid-steered rover as body-velocity
// measurements of two points: the wheel-axle centre c (lever arm l_c from the
// IMU), whose forward speed the wheels measure, and the contact centre n
// (lever arm l_n), which has no sideways velocity:
//   forward  z = (1 - s) r (w_FL + w_FR + w_RL + w_RR) / 4,  h = e_x^T (R^T v + w x l_c)
//   lateral  z = 0 (non-holonomic, optional),             h = e_y^T (R^T v + w x l_n)
//   yaw rate z = r (w_R - w_L) / (track * scrub) (optional), h = e_z^T w
// with w = w_m - b_g and s = s0 + k tilt the expected slip from a
// wheel-terrain calibration (tilt from the current attitude; treated as
// known, not differentiated). Linearised: d(R^T v) = R^T dv + [R^T v]x dtheta,
// d(w x l) = [l]x dbg. The forward noise grows with speed (slip left after
// compensation) and with the estimated slip, the disagreement between the
// front and rear wheels of a side.

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

  /// Body velocities from (averaged) wheel rates, before slip compensation.
  WheelVelocity FromWheelRates(const std::array<double, 4>& wheel_rate_rad_s) const;

  /// The expected slip ratio at attitude R_local_body.
  double ExpectedSlip(const Eigen::Matrix3d& R_local_body) const;

  /// Rows: forward, lateral, yaw rate; unused rows have zero Jacobian and
  /// residual (they do not change the update) and unit noise.
  LinearisedMeasurement<3, 3> Linearise(const FilterState& state, const WheelVelocity& z,
                                        const Eigen::Vector3d& gyro_rad_s) const;

  /// Gates and applies the update; `gyro_rad_s` is the latest raw gyro reading.
  UpdateOutcome Update(FilterState& state, const WheelVelocity& z,
                       const Eigen::Vector3d& gyro_rad_s) const;

  int dof() const { return dof_; }
  double gate() const { return gate_; }

 private:
  WheelOdometryOptions options_;
  int dof_;
  double gate_;
};

}  // namespace rover::estimator

#endif  // ROVER_ESTIMATOR_ESKF_UPDATE_WHEEL_ODOMETRY_UPDATER_H_
