#ifndef ROVER_ESTIMATOR_ESKF_PROPAGATOR_IMU_PROPAGATOR_H_
#define ROVER_ESTIMATOR_ESKF_PROPAGATOR_IMU_PROPAGATOR_H_

// Strap-down propagation of the nominal state and its error covariance from
// one IMU sample to the next.
//
// Nominal integration (second order; exact for angular rate and specific
// force varying linearly over the step, apart from the attitude's
// non-commutativity, which is second order in the rate change):
//   w   = (w_k + w_k1) / 2 - b_g
//   R1  = R0 Exp(w dt)                                   (closed-form SO(3) exp)
//   a_k = R0 (f_k - b_a) + g,   a_k1 = R1 (f_k1 - b_a) + g
//   v1  = v0 + dt (a_k + a_k1) / 2                       (trapezoid)
//   p1  = p0 + v0 dt + dt^2 (2 a_k + a_k1) / 6           (exact for linear a)
// with g = (0, 0, -gravity). Biases are constant over a step.
//
// Error transition: Phi is the exact Jacobian of that discrete step with
// respect to the error state, so covariance and mean follow the same
// integrator. Process noise: the continuous-time model
//   d(dp) = dv,  d(dv) = -R [f - b_a]x dtheta - R dba - R n_a,
//   d(dtheta) = -[w]x dtheta - dbg - n_g,  d(dba) = n_ba,  d(dbg) = n_bg,
// discretised with the Van Loan integral Q = int_0^dt Phi(s) G Qc G^T Phi(s)^T ds,
// expanded in powers of dt (for constant R and f over the step): every term
// of each noise source's leading order in each block, up to dt^5 (position
// from the bias walks); the omitted terms are smaller by a factor of order
// dt |F| ~ 1e-3 at 400 Hz. See README.md.

#include <Eigen/Core>

#include "estimator/eskf/eskf_input.h"
#include "estimator/eskf/eskf_options.h"
#include "estimator/eskf/state/filter_state.h"

namespace rover::estimator {

/// The non-trivial 3x3 blocks of one step's error transition Phi (all other
/// blocks are identity or zero; Phi_pv = dt I).
struct StepTransition {
  double dt_s = 0.0;
  Eigen::Matrix3d p_theta, p_ba, p_bg;
  Eigen::Matrix3d v_theta, v_ba, v_bg;
  Eigen::Matrix3d theta_theta, theta_bg;

  /// X <- Phi X for any matrix X with 15 rows (in place).
  template <typename Derived>
  void ApplyLeft(Eigen::MatrixBase<Derived>& X) const;
};

/// The result of integrating one step, before it is committed.
struct PropagationStep {
  NominalState next;
  StepTransition phi;
};

class ImuPropagator {
 public:
  explicit ImuPropagator(const ImuNoiseOptions& options);

  /// Integrates `from` over [m0.stamp, m1.stamp] with the readings m0 and m1
  /// (from.stamp must equal m0.stamp). A negative interval integrates back in
  /// time, which the filter uses to clone slightly late triggers.
  PropagationStep Integrate(const NominalState& from, const ImuMeasurement& m0,
                            const ImuMeasurement& m1) const;

  /// Propagates `state` over [m0.stamp, m1.stamp]: nominal state, core
  /// covariance (Phi P Phi^T + Q) and the pending cross-covariance transition.
  void Propagate(FilterState& state, const ImuMeasurement& m0, const ImuMeasurement& m1) const;

  /// The discrete process noise of a step of length dt_s at attitude R with
  /// bias-corrected specific force f (Van Loan series to dt^3).
  Matrix15d ProcessNoise(double dt_s, const Eigen::Matrix3d& R_local_body,
                         const Eigen::Vector3d& f_body_m_s2) const;

  /// Gravity in the local frame, (0, 0, -g).
  const Eigen::Vector3d& gravity_local_m_s2() const { return gravity_local_m_s2_; }

 private:
  ImuNoiseOptions options_;
  Eigen::Vector3d gravity_local_m_s2_;
  double accel_noise_var_ = 0.0;  ///< (m/s^2)^2 / Hz
  double gyro_noise_var_ = 0.0;
  double accel_walk_var_ = 0.0;
  double gyro_walk_var_ = 0.0;
};

template <typename Derived>
void StepTransition::ApplyLeft(Eigen::MatrixBase<Derived>& X) const {
  // Row blocks in dependency order so the update can run in place: p uses the
  // old v and theta, v uses the old theta, theta uses bg (unchanged).
  auto p = X.template middleRows<3>(kDp);
  auto v = X.template middleRows<3>(kDv);
  auto th = X.template middleRows<3>(kDtheta);
  const auto ba = X.template middleRows<3>(kDba);
  const auto bg = X.template middleRows<3>(kDbg);
  p += dt_s * v;
  p.noalias() += p_theta * th;
  p.noalias() += p_ba * ba;
  p.noalias() += p_bg * bg;
  v.noalias() += v_theta * th;
  v.noalias() += v_ba * ba;
  v.noalias() += v_bg * bg;
  // theta <- theta_theta * theta + theta_bg * bg needs a temporary for theta.
  const Eigen::Matrix<double, 3, Derived::ColsAtCompileTime, 0, 3, Derived::MaxColsAtCompileTime>
      th_old = th;
  th.noalias() = theta_theta * th_old;
  th.noalias() += theta_bg * bg;
}

}  // namespace rover::estimator

#endif  // ROVER_ESTIMATOR_ESKF_PROPAGATOR_IMU_PROPAGATOR_H_
