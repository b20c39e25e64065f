#include "estimator/eskf/update/wheel_odometry_updater.h"

#include <cmath>

#include "core/geometry/so3.h"
#include "estimator/eskf/update/chi_square_gate.h"

namespace rover::estimator {

WheelOdometryUpdater::WheelOdometryUpdater(const WheelOdometryOptions& options)
    : options_(options),
      dof_(1 + (options.use_nonholonomic ? 1 : 0) + (options.use_yaw_rate ? 1 : 0)),
      gate_(ChiSquareGate(dof_, options.gate_probability)) {}

WheelVelocity WheelOdometryUpdater::FromWheelRates(const std::array<double, 4>& w) const {
  const double r = options_.wheel_radius_m;
  WheelVelocity out;
  out.forward_m_s = r * 0.25 * (w[kFrontLeft] + w[kFrontRight] + w[kRearLeft] + w[kRearRight]);
  out.slip_m_s =
      r * 0.5 * (std::abs(w[kFrontLeft] - w[kRearLeft]) + std::abs(w[kFrontRight] - w[kRearRight]));
  const double left = 0.5 * (w[kFrontLeft] + w[kRearLeft]);
  const double right = 0.5 * (w[kFrontRight] + w[kRearRight]);
  out.yaw_rate_rad_s = r * (right - left) / (options_.track_m * options_.yaw_scrub_factor);
  return out;
}

LinearisedMeasurement<3, 3> WheelOdometryUpdater::Linearise(const FilterState& state,
                                                            const WheelVelocity& z,
                                                            const Eigen::Vector3d& gyro) const {
  const NominalState& x = state.core;
  const Eigen::Matrix3d Rt = x.R_local_body.transpose();
  const Eigen::Vector3d w = gyro - x.gyro_bias_rad_s;
  const Eigen::Vector3d& l = options_.lever_arm_body_m;
  const Eigen::Vector3d v_body = Rt * x.v_local_m_s + w.cross(l);

  LinearisedMeasurement<3, 3> m;
  m.block_offsets = {kDv, kDtheta, kDbg};
  const Eigen::Matrix3d dv = Rt;
  const Eigen::Matrix3d dtheta = skew(Rt * x.v_local_m_s);
  const Eigen::Matrix3d dbg = skew(l);
  const double sigma_fwd = options_.forward_sigma_m_s +
                           options_.forward_sigma_per_speed * std::abs(z.forward_m_s) +
                           options_.slip_sigma_gain * z.slip_m_s;
  m.R.setIdentity();
  // Row 0: forward velocity.
  m.residual(0) = z.forward_m_s - v_body.x();
  m.H.block<1, 3>(0, 0) = dv.row(0);
  m.H.block<1, 3>(0, 3) = dtheta.row(0);
  m.H.block<1, 3>(0, 6) = dbg.row(0);
  m.R(0, 0) = sigma_fwd * sigma_fwd;
  if (options_.use_nonholonomic) {
    m.residual(1) = 0.0 - v_body.y();
    m.H.block<1, 3>(1, 0) = dv.row(1);
    m.H.block<1, 3>(1, 3) = dtheta.row(1);
    m.H.block<1, 3>(1, 6) = dbg.row(1);
    m.R(1, 1) = options_.lateral_sigma_m_s * options_.lateral_sigma_m_s;
  }
  if (options_.use_yaw_rate) {
    m.residual(2) = z.yaw_rate_rad_s - w.z();
    m.H(2, 8) = -1.0;  // d(w_z)/d(bg_z)
    m.R(2, 2) = options_.yaw_rate_sigma_rad_s * options_.yaw_rate_sigma_rad_s;
  }
  return m;
}

UpdateOutcome WheelOdometryUpdater::Update(FilterState& state, const WheelVelocity& z,
                                           const Eigen::Vector3d& gyro_rad_s) const {
  return KalmanUpdate(state, Linearise(state, z, gyro_rad_s), gate_);
}

}  // namespace rover::estimator
