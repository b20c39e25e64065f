#ifndef ROVER_HIL_SIM_IMU_ERROR_MODEL_H_
#define ROVER_HIL_SIM_IMU_ERROR_MODEL_H_

// Stochastic IMU errors with datasheet-style parameters: white noise from the
// noise densities, a bias random walk and a turn-on bias. Seeded, so the same
// seed gives the same sample stream bit for bit.

#include <Eigen/Core>
#include <random>

namespace rover::sim {

/// Defaults are an MTi-10-class MEMS unit.
struct ImuErrorOptions {
  double gyro_noise_density_rad_s_sqrt_hz = 1.7e-4;  // 0.01 deg/s/sqrt(Hz)
  double accel_noise_density_m_s2_sqrt_hz = 6.0e-4;  // 60 ug/sqrt(Hz)
  double gyro_bias_random_walk_rad_s2_sqrt_hz = 2.0e-5;
  double accel_bias_random_walk_m_s3_sqrt_hz = 1.0e-4;
  double gyro_turn_on_bias_sigma_rad_s = 3.5e-3;  // 0.2 deg/s
  double accel_turn_on_bias_sigma_m_s2 = 0.03;
  uint64_t seed = 1;
};

/// A corrupted IMU sample.
struct ImuMeasurement {
  Eigen::Vector3d angular_velocity_rad_s;
  Eigen::Vector3d linear_acceleration_m_s2;
};

class ImuErrorModel {
 public:
  explicit ImuErrorModel(const ImuErrorOptions& options);

  /// Corrupts one ideal sample; `dt_s` is the sample period, which scales the
  /// discrete noise (sigma_d = density / sqrt(dt)) and the bias walk
  /// (sigma_b = density * sqrt(dt)).
  ImuMeasurement Apply(const Eigen::Vector3d& omega_true_rad_s,
                       const Eigen::Vector3d& specific_force_true_m_s2, double dt_s);

  const Eigen::Vector3d& gyro_bias_rad_s() const { return gyro_bias_rad_s_; }
  const Eigen::Vector3d& accel_bias_m_s2() const { return accel_bias_m_s2_; }

 private:
  Eigen::Vector3d Gaussian3(double sigma);

  ImuErrorOptions options_;
  std::mt19937_64 rng_;
  std::normal_distribution<double> unit_normal_{0.0, 1.0};
  Eigen::Vector3d gyro_bias_rad_s_;
  Eigen::Vector3d accel_bias_m_s2_;
};

}  // namespace rover::sim

#endif  // ROVER_HIL_SIM_IMU_ERROR_MODEL_H_
