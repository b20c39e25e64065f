#include "firmware/roverd/sensor_calibration.h"

namespace rover::roverd {

estimator::EskfOptions FilterOptionsFromCalibration(const calib::ImuCalibration& imu,
                                                    const std::string& path) {
  // A given file is complete (absent keys take the defaults); without one the
  // dataset's own noise figures are the best knowledge.
  estimator::EskfOptions o =
      path.empty() ? estimator::EskfOptions{} : estimator::EskfOptions::LoadFile(path);
  // The rate is a property of the data, not a tuning choice.
  if (imu.rate_hz > 0.0) o.imu.rate_hz = imu.rate_hz;
  if (path.empty()) {
    const auto set = [](double v, double* option) {
      if (v > 0.0) *option = v;
    };
    set(imu.gyro_noise_density_rad_s_sqrt_hz, &o.imu.gyro_noise_density_rad_s_sqrt_hz);
    set(imu.gyro_random_walk_rad_s2_sqrt_hz, &o.imu.gyro_bias_random_walk_rad_s2_sqrt_hz);
    set(imu.accel_noise_density_m_s2_sqrt_hz, &o.imu.accel_noise_density_m_s2_sqrt_hz);
    set(imu.accel_random_walk_m_s3_sqrt_hz, &o.imu.accel_bias_random_walk_m_s3_sqrt_hz);
    o.wheels.enabled = false;  // no wheel drives are replayed
  }
  o.clones.max_clones = estimator::kMaxClones;  // 5 keyframes + frames in flight
  return o;
}

}  // namespace rover::roverd
