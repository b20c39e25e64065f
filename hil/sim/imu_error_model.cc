#include "hil/sim/imu_error_model.h"

#include <cmath>

namespace rover::sim {

ImuErrorModel::ImuErrorModel(const ImuErrorOptions& options)
    : options_(options), rng_(options.seed) {
  gyro_bias_rad_s_ = Gaussian3(options_.gyro_turn_on_bias_sigma_rad_s);
  accel_bias_m_s2_ = Gaussian3(options_.accel_turn_on_bias_sigma_m_s2);
}

Eigen::Vector3d ImuErrorModel::Gaussian3(double sigma) {
  // Draw in a fixed order so the stream does not depend on evaluation order.
  const double x = unit_normal_(rng_);
  const double y = unit_normal_(rng_);
  const double z = unit_normal_(rng_);
  return sigma * Eigen::Vector3d(x, y, z);
}

ImuMeasurement ImuErrorModel::Apply(const Eigen::Vector3d& omega_true_rad_s,
                                    const Eigen::Vector3d& specific_force_true_m_s2, double dt_s) {
  const double sqrt_dt = std::sqrt(dt_s);
  gyro_bias_rad_s_ += Gaussian3(options_.gyro_bias_random_walk_rad_s2_sqrt_hz * sqrt_dt);
  accel_bias_m_s2_ += Gaussian3(options_.accel_bias_random_walk_m_s3_sqrt_hz * sqrt_dt);
  ImuMeasurement m;
  m.angular_velocity_rad_s = omega_true_rad_s + gyro_bias_rad_s_ +
                             Gaussian3(options_.gyro_noise_density_rad_s_sqrt_hz / sqrt_dt);
  m.linear_acceleration_m_s2 = specific_force_true_m_s2 + accel_bias_m_s2_ +
                               Gaussian3(options_.accel_noise_density_m_s2_sqrt_hz / sqrt_dt);
  return m;
}

}  // namespace rover::sim
