#include "estimator/eskf/update/wheel_odometry_updater.h"

#include <algorithm>
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

double WheelOdometryUpdater::ExpectedSlip(const Eigen::Matrix3d& R) const {
  const double tilt = std::acos(std::clamp(R(2, 2), -1.0, 1.0));
  return std::clamp(options_.slip_ratio_base + options_.slip_ratio_per_tilt_rad * tilt, 0.0, 0.9);
}

LinearisedMeasurement<3, 3> WheelOdometryUpdater::Linearise(const FilterState& state,
                                                            const WheelVelocity& z,
                                                            const Eigen::Vector3d& gyro) const {
  const NominalState& x = state.core;
  const Eigen::Matrix3d Rt = x.R_local_body.transpose();
  const Eigen::Vector3d w = gyro - x.gyro_bias_rad_s;
  const Eigen::Vector3d v_rot = Rt * x.v_local_m_s;
  const Eigen::Vector3d v_axle = v_rot + w.cross(options_.lever_arm_body_m);
  const Eigen::Vector3d v_contact = v_rot + w.cross(options_.nonholonomic_point_body_m);
  const double forward = (1.0 - ExpectedSlip(x.R_local_body)) * z.forward_m_s;

  LinearisedMeasurement<3, 3> m;
  m.block_offsets = {kDv, kDtheta, kDbg};
  const Eigen::Matrix3d dv = Rt;
  const Eigen::Matrix3d dtheta = skew(v_rot);
  const Eigen::Matrix3d dbg_axle = skew(options_.lever_arm_body_m);
  const Eigen::Matrix3d dbg_contact = skew(options_.nonholonomic_point_body_m);
  const double sigma_fwd = options_.forward_sigma_m_s +
                           options_.forward_sigma_per_speed * std::abs(forward) +
                           options_.slip_sigma_gain * z.slip_m_s;
  m.R.setIdentity();
  // Row 0: forward velocity.
  m.residual(0) = forward - v_axle.x();
  m.H.block<1, 3>(0, 0) = dv.row(0);
  m.H.block<1, 3>(0, 3) = dtheta.row(0);
  m.H.block<1, 3>(0, 6) = dbg_axle.row(0);
  m.R(0, 0) = sigma_fwd * sigma_fwd;
  if (options_.use_nonholonomic) {
    m.residual(1) = 0.0 - v_contact.y();
    m.H.block<1, 3>(1, 0) = dv.row(1);
    m.H.block<1, 3>(1, 3) = dtheta.row(1);
    m.H.block<1, 3>(1, 6) = dbg_contact.row(1);
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
