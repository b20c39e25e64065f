#ifndef ROVER_CORE_CALIB_IMU_CALIBRATION_H_
#define ROVER_CORE_CALIB_IMU_CALIBRATION_H_

// The IMU's calibration: rate, noise figures (continuous-time densities, as
// Kalibr and the EuRoC sensor.yaml state them) and its pose on the body.

#include <Eigen/Geometry>
#include <optional>

#include "core/calib/validation.h"

namespace rover::calib {

/// One IMU's calibration.
struct ImuCalibration {
  double rate_hz = 0.0;
  double gyro_noise_density_rad_s_sqrt_hz = 0.0;  ///< white noise of the rate
  double gyro_random_walk_rad_s2_sqrt_hz = 0.0;   ///< bias diffusion
  double accel_noise_density_m_s2_sqrt_hz = 0.0;  ///< white noise of the specific force
  double accel_random_walk_m_s3_sqrt_hz = 0.0;    ///< bias diffusion
  Eigen::Isometry3d T_body_imu = Eigen::Isometry3d::Identity();  ///< EuRoC's T_BS

  /// The first unusable field (named as the member) and why, or nullopt:
  /// the rate and every noise figure finite and > 0, T_body_imu a rigid
  /// transform.
  std::optional<FieldProblem> Problem() const;

  /// Exact equality of every field (T_body_imu element by element).
  friend bool operator==(const ImuCalibration& a, const ImuCalibration& b) {
    return a.rate_hz == b.rate_hz &&
           a.gyro_noise_density_rad_s_sqrt_hz == b.gyro_noise_density_rad_s_sqrt_hz &&
           a.gyro_random_walk_rad_s2_sqrt_hz == b.gyro_random_walk_rad_s2_sqrt_hz &&
           a.accel_noise_density_m_s2_sqrt_hz == b.accel_noise_density_m_s2_sqrt_hz &&
           a.accel_random_walk_m_s3_sqrt_hz == b.accel_random_walk_m_s3_sqrt_hz &&
           a.T_body_imu.matrix() == b.T_body_imu.matrix();
  }
};

}  // namespace rover::calib

#endif  // ROVER_CORE_CALIB_IMU_CALIBRATION_H_
