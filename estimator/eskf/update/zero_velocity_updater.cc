#include "estimator/eskf/update/zero_velocity_updater.h"

#include <cmath>

namespace rover::estimator {

ZeroVelocityUpdater::ZeroVelocityUpdater(const ZuptOptions& options, const ImuNoiseOptions& imu)
    : options_(options),
      gyro_sample_sigma_rad_s_(imu.gyro_noise_density_rad_s_sqrt_hz * imu.noise_inflation *
                               std::sqrt(imu.rate_hz)),
      gate_(0.0) {}

LinearisedMeasurement<6, 2> ZeroVelocityUpdater::Linearise(const FilterState& state,
                                                           const Eigen::Vector3d& mean_gyro,
                                                           int window_samples) const {
  LinearisedMeasurement<6, 2> m;
  m.block_offsets = {kDv, kDbg};
  m.residual.head<3>() = -state.core.v_local_m_s;
  m.residual.tail<3>() = mean_gyro - state.core.gyro_bias_rad_s;
  m.H.block<3, 3>(0, 0).setIdentity();
  m.H.block<3, 3>(3, 3).setIdentity();
  const double sv = options_.velocity_sigma_m_s;
  // The window mean of white noise, plus a floor for slow vibration.
  const double sg =
      gyro_sample_sigma_rad_s_ / std::sqrt(static_cast<double>(window_samples)) + 1e-5;
  m.R.setZero();
  m.R.diagonal() << sv * sv, sv * sv, sv * sv, sg * sg, sg * sg, sg * sg;
  return m;
}

UpdateOutcome ZeroVelocityUpdater::Update(FilterState& state, const Eigen::Vector3d& mean_gyro,
                                          int window_samples) const {
  return KalmanUpdate(state, Linearise(state, mean_gyro, window_samples), gate_);
}

}  // namespace rover::estimator
