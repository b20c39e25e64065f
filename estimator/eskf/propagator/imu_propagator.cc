#include "estimator/eskf/propagator/imu_propagator.h"

#include "core/geometry/quaternion.h"
#include "core/geometry/so3.h"

namespace rover::estimator {

ImuPropagator::ImuPropagator(const ImuNoiseOptions& options)
    : options_(options), gravity_local_m_s2_(0.0, 0.0, -options.gravity_m_s2) {
  const double inflate = options.noise_inflation;
  const double sa = options.accel_noise_density_m_s2_sqrt_hz * inflate;
  const double sg = options.gyro_noise_density_rad_s_sqrt_hz * inflate;
  accel_noise_var_ = sa * sa;
  gyro_noise_var_ = sg * sg;
  accel_walk_var_ =
      options.accel_bias_random_walk_m_s3_sqrt_hz * options.accel_bias_random_walk_m_s3_sqrt_hz;
  gyro_walk_var_ =
      options.gyro_bias_random_walk_rad_s2_sqrt_hz * options.gyro_bias_random_walk_rad_s2_sqrt_hz;
}

PropagationStep ImuPropagator::Integrate(const NominalState& from, const ImuMeasurement& m0,
                                         const ImuMeasurement& m1) const {
  PropagationStep step;
  const double dt = (m1.stamp - m0.stamp).ToSeconds();
  const Eigen::Vector3d w =
      0.5 * (m0.angular_velocity_rad_s + m1.angular_velocity_rad_s) - from.gyro_bias_rad_s;
  const Eigen::Vector3d phi = w * dt;
  const Eigen::Matrix3d dR = ExpSO3(phi);
  const Eigen::Matrix3d& R0 = from.R_local_body;
  const Eigen::Matrix3d R1 = R0 * dR;
  const Eigen::Vector3d u0 = m0.linear_acceleration_m_s2 - from.accel_bias_m_s2;
  const Eigen::Vector3d u1 = m1.linear_acceleration_m_s2 - from.accel_bias_m_s2;
  const Eigen::Vector3d a0 = R0 * u0 + gravity_local_m_s2_;
  const Eigen::Vector3d a1 = R1 * u1 + gravity_local_m_s2_;

  NominalState& next = step.next;
  next = from;
  next.stamp = m1.stamp;
  next.p_local_body = from.p_local_body + from.v_local_m_s * dt + dt * dt / 6.0 * (2.0 * a0 + a1);
  next.v_local_m_s = from.v_local_m_s + 0.5 * dt * (a0 + a1);
  next.SetAttitude(Boxplus(from.q_local_body, phi));

  // Exact Jacobian of the step above (body-side attitude error).
  StepTransition& t = step.phi;
  t.dt_s = dt;
  const Eigen::Matrix3d dRt = dR.transpose();
  const Eigen::Matrix3d Jr_dt = RightJacobianSO3(phi) * dt;
  const Eigen::Matrix3d R0u0x = R0 * skew(u0);
  const Eigen::Matrix3d R1u1x = R1 * skew(u1);
  const Eigen::Matrix3d R1u1x_dRt = R1u1x * dRt;
  t.theta_theta = dRt;
  t.theta_bg = -Jr_dt;
  t.v_theta = -0.5 * dt * (R0u0x + R1u1x_dRt);
  t.v_ba = -0.5 * dt * (R0 + R1);
  t.v_bg = 0.5 * dt * R1u1x * Jr_dt;
  const double dt2_6 = dt * dt / 6.0;
  t.p_theta = -dt2_6 * (2.0 * R0u0x + R1u1x_dRt);
  t.p_ba = -dt2_6 * (2.0 * R0 + R1);
  t.p_bg = dt2_6 * R1u1x * Jr_dt;
  return step;
}

Matrix15d ImuPropagator::ProcessNoise(double dt, const Eigen::Matrix3d& R,
                                      const Eigen::Vector3d& f) const {
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  const double dt2 = dt * dt;
  const double dt3 = dt2 * dt;
  const double na = accel_noise_var_, ng = gyro_noise_var_;
  const double nba = accel_walk_var_, nbg = gyro_walk_var_;
  const Eigen::Matrix3d Rfx = R * skew(f);

  const double dt4 = dt3 * dt;
  const double dt5 = dt4 * dt;
  const Eigen::Matrix3d RfxRfxT = Rfx * Rfx.transpose();

  Matrix15d Q = Matrix15d::Zero();
  Q.block<3, 3>(kDp, kDp) = (na * dt3 / 3.0 + nba * dt5 / 20.0) * I + (ng * dt5 / 20.0) * RfxRfxT;
  Q.block<3, 3>(kDp, kDv) = (na * dt2 / 2.0 + nba * dt4 / 8.0) * I + (ng * dt4 / 8.0) * RfxRfxT;
  Q.block<3, 3>(kDp, kDtheta) = (-ng * dt3 / 6.0) * Rfx;
  Q.block<3, 3>(kDp, kDba) = (-nba * dt3 / 6.0) * R;
  Q.block<3, 3>(kDp, kDbg) = (nbg * dt4 / 24.0) * Rfx;
  Q.block<3, 3>(kDv, kDv) = (na * dt + nba * dt3 / 3.0) * I + (ng * dt3 / 3.0) * RfxRfxT;
  Q.block<3, 3>(kDv, kDtheta) = (-ng * dt2 / 2.0) * Rfx;
  Q.block<3, 3>(kDv, kDba) = (-nba * dt2 / 2.0) * R;
  Q.block<3, 3>(kDv, kDbg) = (nbg * dt3 / 6.0) * Rfx;
  Q.block<3, 3>(kDtheta, kDtheta) = (ng * dt + nbg * dt3 / 3.0) * I;
  Q.block<3, 3>(kDtheta, kDbg) = (-nbg * dt2 / 2.0) * I;
  Q.block<3, 3>(kDba, kDba) = (nba * dt) * I;
  Q.block<3, 3>(kDbg, kDbg) = (nbg * dt) * I;
  // Mirror the upper triangle.
  for (int r = 0; r < 15; ++r) {
    for (int c = r + 1; c < 15; ++c) Q(c, r) = Q(r, c);
  }
  return Q;
}

void ImuPropagator::Propagate(FilterState& state, const ImuMeasurement& m0,
                              const ImuMeasurement& m1) const {
  const PropagationStep step = Integrate(state.core, m0, m1);
  const Eigen::Vector3d f0 = m0.linear_acceleration_m_s2 - state.core.accel_bias_m_s2;
  const Matrix15d Q = ProcessNoise(step.phi.dt_s, state.core.R_local_body, f0);

  // P_cc <- Phi P_cc Phi^T + Q, as Phi (Phi P_cc)^T using P_cc = P_cc^T.
  Matrix15d A = state.P.topLeftCorner<15, 15>();
  step.phi.ApplyLeft(A);
  Matrix15d B = A.transpose();
  step.phi.ApplyLeft(B);
  state.P.topLeftCorner<15, 15>() = 0.5 * (B + B.transpose()) + Q;
  if (state.clone_count > 0) step.phi.ApplyLeft(state.pending_transition);
  state.core = step.next;
}

}  // namespace rover::estimator
