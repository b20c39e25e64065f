#include "estimator/feed/filter_options.h"

#include "core/config/config.h"

namespace rover::estimator {
namespace {

// True if the YAML document `root` sets `section`.`key`.
bool FileSets(const ConfigNode& root, const char* section, const char* key) {
  return root.Has(section) && root.Child(section).Has(key);
}

// Steps 1-4: what the calibration alone gives.
EskfOptions FromCalibrationAlone(const calib::BoardCalibration& calibration) {
  EskfOptions o;
  const calib::ImuCalibration& imu = calibration.imu;
  const auto set_if_positive = [](double value, double* option) {
    if (value > 0.0) *option = value;
  };
  set_if_positive(imu.rate_hz, &o.imu.rate_hz);
  set_if_positive(imu.gyro_noise_density_rad_s_sqrt_hz, &o.imu.gyro_noise_density_rad_s_sqrt_hz);
  set_if_positive(imu.gyro_random_walk_rad_s2_sqrt_hz, &o.imu.gyro_bias_random_walk_rad_s2_sqrt_hz);
  set_if_positive(imu.accel_noise_density_m_s2_sqrt_hz, &o.imu.accel_noise_density_m_s2_sqrt_hz);
  set_if_positive(imu.accel_random_walk_m_s3_sqrt_hz, &o.imu.accel_bias_random_walk_m_s3_sqrt_hz);
  o.clones.max_clones = kMaxClones;
  o.wheels.enabled = calibration.wheels.has_value();
  if (const std::optional<calib::WheelCalibration>& w = calibration.wheels) {
    o.wheels.wheel_radius_m = w->wheel_radius_m;
    o.wheels.track_m = w->track_m;
    o.wheels.yaw_scrub_factor = w->yaw_scrub_factor;
    o.wheels.lever_arm_body_m = w->lever_arm_body_m;
    o.wheels.nonholonomic_point_body_m = w->nonholonomic_point_body_m;
    o.wheels.slip_ratio_base = w->slip_ratio_base;
    o.wheels.slip_ratio_per_tilt_rad = w->slip_ratio_per_tilt_rad;
  }
  return o;
}

// Step 5: the file's keys over `base`. Load() fills every absent key with its
// default, so what the calibration gave is put back unless the file sets it.
EskfOptions OverlayFile(const EskfOptions& base, const std::string& path) {
  const ConfigNode root = ConfigNode::LoadFile(path);
  EskfOptions o = EskfOptions::Load(root);
  root.CheckNoUnknownKeysRecursive();
  const auto keep = [&](const char* section, const char* key, auto group, auto field) {
    if (!FileSets(root, section, key)) (o.*group).*field = (base.*group).*field;
  };
  keep("imu", "rate_hz", &EskfOptions::imu, &ImuNoiseOptions::rate_hz);
  keep("imu", "gyro_noise_density_rad_s_sqrt_hz", &EskfOptions::imu,
       &ImuNoiseOptions::gyro_noise_density_rad_s_sqrt_hz);
  keep("imu", "gyro_bias_random_walk_rad_s2_sqrt_hz", &EskfOptions::imu,
       &ImuNoiseOptions::gyro_bias_random_walk_rad_s2_sqrt_hz);
  keep("imu", "accel_noise_density_m_s2_sqrt_hz", &EskfOptions::imu,
       &ImuNoiseOptions::accel_noise_density_m_s2_sqrt_hz);
  keep("imu", "accel_bias_random_walk_m_s3_sqrt_hz", &EskfOptions::imu,
       &ImuNoiseOptions::accel_bias_random_walk_m_s3_sqrt_hz);
  keep("clones", "max_clones", &EskfOptions::clones, &CloneOptions::max_clones);
  keep("wheels", "enabled", &EskfOptions::wheels, &WheelOdometryOptions::enabled);
  keep("wheels", "wheel_radius_m", &EskfOptions::wheels, &WheelOdometryOptions::wheel_radius_m);
  keep("wheels", "track_m", &EskfOptions::wheels, &WheelOdometryOptions::track_m);
  keep("wheels", "yaw_scrub_factor", &EskfOptions::wheels, &WheelOdometryOptions::yaw_scrub_factor);
  keep("wheels", "lever_arm_body_m", &EskfOptions::wheels, &WheelOdometryOptions::lever_arm_body_m);
  keep("wheels", "nonholonomic_point_body_m", &EskfOptions::wheels,
       &WheelOdometryOptions::nonholonomic_point_body_m);
  keep("wheels", "slip_ratio_base", &EskfOptions::wheels, &WheelOdometryOptions::slip_ratio_base);
  keep("wheels", "slip_ratio_per_tilt_rad", &EskfOptions::wheels,
       &WheelOdometryOptions::slip_ratio_per_tilt_rad);
  return o;
}

}  // namespace

EskfOptions FilterOptionsFromCalibration(const calib::BoardCalibration& calibration,
                                         const std::string& filter_config_path) {
  const EskfOptions base = FromCalibrationAlone(calibration);
  return filter_config_path.empty() ? base : OverlayFile(base, filter_config_path);
}

vo::StereoOdometryOptions VoOptionsFromCalibration(double camera_rate_hz,
                                                   const std::string& vo_config_path) {
  vo::StereoOdometryOptions o;
  bool rate_from_file = false;
  if (!vo_config_path.empty()) {
    const ConfigNode root = ConfigNode::LoadFile(vo_config_path);
    o = vo::StereoOdometryOptions::Load(root);
    root.CheckNoUnknownKeysRecursive();
    rate_from_file = FileSets(root, "checks", "nominal_rate_hz");
  }
  if (!rate_from_file && camera_rate_hz > 0.0) o.checks.nominal_rate_hz = camera_rate_hz;
  o.Validate();
  return o;
}

}  // namespace rover::estimator
