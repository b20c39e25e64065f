#include "estimator/eskf/eskf_options.h"

#include <cstdio>
#include <string>

namespace rover::estimator {
namespace {

// A section that is absent takes every default.
template <typename Options>
Options LoadSection(const ConfigNode& parent, const char* key) {
  return parent.Has(key) ? Options::Load(parent.Child(key)) : Options{};
}

}  // namespace

ImuNoiseOptions ImuNoiseOptions::Load(const ConfigNode& n) {
  ImuNoiseOptions o;
  o.rate_hz = n.GetInRange<double>("rate_hz", 10.0, 10000.0, o.rate_hz);
  o.gyro_noise_density_rad_s_sqrt_hz = n.GetInRange<double>(
      "gyro_noise_density_rad_s_sqrt_hz", 1e-7, 1.0, o.gyro_noise_density_rad_s_sqrt_hz);
  o.gyro_bias_random_walk_rad_s2_sqrt_hz = n.GetInRange<double>(
      "gyro_bias_random_walk_rad_s2_sqrt_hz", 1e-9, 1.0, o.gyro_bias_random_walk_rad_s2_sqrt_hz);
  o.accel_noise_density_m_s2_sqrt_hz = n.GetInRange<double>(
      "accel_noise_density_m_s2_sqrt_hz", 1e-7, 10.0, o.accel_noise_density_m_s2_sqrt_hz);
  o.accel_bias_random_walk_m_s3_sqrt_hz = n.GetInRange<double>(
      "accel_bias_random_walk_m_s3_sqrt_hz", 1e-9, 10.0, o.accel_bias_random_walk_m_s3_sqrt_hz);
  o.gyro_range_rad_s = n.GetInRange<double>("gyro_range_rad_s", 0.1, 1e4, o.gyro_range_rad_s);
  o.accel_range_m_s2 = n.GetInRange<double>("accel_range_m_s2", 10.0, 1e4, o.accel_range_m_s2);
  o.gravity_m_s2 = n.GetInRange<double>("gravity_m_s2", 0.1, 30.0, o.gravity_m_s2);
  o.noise_inflation = n.GetInRange<double>("noise_inflation", 1.0, 100.0, o.noise_inflation);
  return o;
}

InitOptions InitOptions::Load(const ConfigNode& n) {
  InitOptions o;
  o.window_s = n.GetInRange<double>("window_s", 0.05, 10.0, o.window_s);
  o.accel_std_threshold_m_s2 =
      n.GetInRange<double>("accel_std_threshold_m_s2", 1e-4, 10.0, o.accel_std_threshold_m_s2);
  o.gyro_std_threshold_rad_s =
      n.GetInRange<double>("gyro_std_threshold_rad_s", 1e-5, 1.0, o.gyro_std_threshold_rad_s);
  o.velocity_sigma_m_s =
      n.GetInRange<double>("velocity_sigma_m_s", 1e-6, 10.0, o.velocity_sigma_m_s);
  o.accel_bias_sigma_m_s2 =
      n.GetInRange<double>("accel_bias_sigma_m_s2", 1e-6, 10.0, o.accel_bias_sigma_m_s2);
  o.gyro_bias_sigma_floor_rad_s =
      n.GetInRange<double>("gyro_bias_sigma_floor_rad_s", 1e-7, 1.0, o.gyro_bias_sigma_floor_rad_s);
  return o;
}

CloneOptions CloneOptions::Load(const ConfigNode& n) {
  CloneOptions o;
  o.max_clones = n.GetInRange<int>("max_clones", 2, kMaxClones, o.max_clones);
  o.max_trigger_lateness_s =
      n.GetInRange<double>("max_trigger_lateness_s", 0.0, 0.2, o.max_trigger_lateness_s);
  o.stamp_tolerance_s = n.GetInRange<double>("stamp_tolerance_s", 0.0, 0.01, o.stamp_tolerance_s);
  return o;
}

RelativePoseOptions RelativePoseOptions::Load(const ConfigNode& n) {
  RelativePoseOptions o;
  o.max_delay_s = n.GetInRange<double>("max_delay_s", 0.0, 5.0, o.max_delay_s);
  o.gate_probability = n.GetInRange<double>("gate_probability", 0.5, 1.0, o.gate_probability);
  o.covariance_inflation =
      n.GetInRange<double>("covariance_inflation", 0.01, 1e4, o.covariance_inflation);
  return o;
}

WheelOdometryOptions WheelOdometryOptions::Load(const ConfigNode& n) {
  WheelOdometryOptions o;
  o.enabled = n.Get<bool>("enabled", o.enabled);
  o.wheel_radius_m = n.GetInRange<double>("wheel_radius_m", 0.01, 2.0, o.wheel_radius_m);
  o.track_m = n.GetInRange<double>("track_m", 0.05, 5.0, o.track_m);
  o.yaw_scrub_factor = n.GetInRange<double>("yaw_scrub_factor", 0.5, 5.0, o.yaw_scrub_factor);
  o.lever_arm_body_m = n.Get<Eigen::Vector3d>("lever_arm_body_m", o.lever_arm_body_m);
  o.nonholonomic_point_body_m =
      n.Get<Eigen::Vector3d>("nonholonomic_point_body_m", o.nonholonomic_point_body_m);
  o.slip_ratio_base = n.GetInRange<double>("slip_ratio_base", 0.0, 0.9, o.slip_ratio_base);
  o.slip_ratio_per_tilt_rad =
      n.GetInRange<double>("slip_ratio_per_tilt_rad", 0.0, 10.0, o.slip_ratio_per_tilt_rad);
  o.update_period_s = n.GetInRange<double>("update_period_s", 0.0, 1.0, o.update_period_s);
  o.forward_sigma_m_s = n.GetInRange<double>("forward_sigma_m_s", 1e-5, 10.0, o.forward_sigma_m_s);
  o.forward_sigma_per_speed =
      n.GetInRange<double>("forward_sigma_per_speed", 0.0, 1.0, o.forward_sigma_per_speed);
  o.slip_sigma_gain = n.GetInRange<double>("slip_sigma_gain", 0.0, 100.0, o.slip_sigma_gain);
  o.use_nonholonomic = n.Get<bool>("use_nonholonomic", o.use_nonholonomic);
  o.lateral_sigma_m_s = n.GetInRange<double>("lateral_sigma_m_s", 1e-5, 10.0, o.lateral_sigma_m_s);
  o.use_yaw_rate = n.Get<bool>("use_yaw_rate", o.use_yaw_rate);
  o.yaw_rate_sigma_rad_s =
      n.GetInRange<double>("yaw_rate_sigma_rad_s", 1e-5, 10.0, o.yaw_rate_sigma_rad_s);
  o.max_delay_s = n.GetInRange<double>("max_delay_s", 0.0, 1.0, o.max_delay_s);
  o.gate_probability = n.GetInRange<double>("gate_probability", 0.5, 1.0, o.gate_probability);
  return o;
}

ZuptOptions ZuptOptions::Load(const ConfigNode& n) {
  ZuptOptions o;
  o.enabled = n.Get<bool>("enabled", o.enabled);
  o.window_s = n.GetInRange<double>("window_s", 0.01, 5.0, o.window_s);
  o.wheel_rate_threshold_rad_s =
      n.GetInRange<double>("wheel_rate_threshold_rad_s", 0.0, 10.0, o.wheel_rate_threshold_rad_s);
  o.gyro_threshold_rad_s =
      n.GetInRange<double>("gyro_threshold_rad_s", 1e-5, 1.0, o.gyro_threshold_rad_s);
  o.accel_std_threshold_m_s2 =
      n.GetInRange<double>("accel_std_threshold_m_s2", 1e-4, 10.0, o.accel_std_threshold_m_s2);
  o.allow_imu_only = n.Get<bool>("allow_imu_only", o.allow_imu_only);
  o.velocity_sigma_m_s =
      n.GetInRange<double>("velocity_sigma_m_s", 1e-6, 1.0, o.velocity_sigma_m_s);
  o.period_s = n.GetInRange<double>("period_s", 0.0, 10.0, o.period_s);
  return o;
}

EskfHealthOptions EskfHealthOptions::Load(const ConfigNode& n) {
  EskfHealthOptions o;
  o.max_imu_gap_s = n.GetInRange<double>("max_imu_gap_s", 1e-4, 10.0, o.max_imu_gap_s);
  o.recovery_s = n.GetInRange<double>("recovery_s", 0.0, 60.0, o.recovery_s);
  o.aiding_timeout_s = n.GetInRange<double>("aiding_timeout_s", 0.01, 600.0, o.aiding_timeout_s);
  return o;
}

EskfOptions EskfOptions::Load(const ConfigNode& n) {
  EskfOptions o;
  o.imu = LoadSection<ImuNoiseOptions>(n, "imu");
  o.init = LoadSection<InitOptions>(n, "init");
  o.clones = LoadSection<CloneOptions>(n, "clones");
  o.relative_pose = LoadSection<RelativePoseOptions>(n, "relative_pose");
  o.wheels = LoadSection<WheelOdometryOptions>(n, "wheels");
  o.zupt = LoadSection<ZuptOptions>(n, "zupt");
  o.health = LoadSection<EskfHealthOptions>(n, "health");
  return o;
}

EskfOptions EskfOptions::LoadFile(const std::string& path) {
  const ConfigNode root = ConfigNode::LoadFile(path);
  EskfOptions o = Load(root);
  root.CheckNoUnknownKeysRecursive();
  return o;
}

namespace {

// Writes "  key: value" lines of one section.
class YamlSection {
 public:
  YamlSection(std::string* out, const char* name) : out_(out) {
    *out_ += std::string(name) + ":\n";
  }
  void Put(const char* key, double value) {
    char text[40];
    std::snprintf(text, sizeof(text), "%.17g", value);
    Line(key, text);
  }
  void Put(const char* key, int value) { Line(key, std::to_string(value)); }
  void Put(const char* key, bool value) { Line(key, value ? "true" : "false"); }
  void Put(const char* key, const Eigen::Vector3d& v) {
    char text[128];
    std::snprintf(text, sizeof(text), "[%.17g, %.17g, %.17g]", v.x(), v.y(), v.z());
    Line(key, text);
  }

 private:
  void Line(const char* key, const std::string& value) {
    *out_ += std::string("  ") + key + ": " + value + "\n";
  }
  std::string* out_;
};

}  // namespace

std::string ToYaml(const EskfOptions& o) {
  std::string out;
  YamlSection imu(&out, "imu");
  imu.Put("rate_hz", o.imu.rate_hz);
  imu.Put("gyro_noise_density_rad_s_sqrt_hz", o.imu.gyro_noise_density_rad_s_sqrt_hz);
  imu.Put("gyro_bias_random_walk_rad_s2_sqrt_hz", o.imu.gyro_bias_random_walk_rad_s2_sqrt_hz);
  imu.Put("accel_noise_density_m_s2_sqrt_hz", o.imu.accel_noise_density_m_s2_sqrt_hz);
  imu.Put("accel_bias_random_walk_m_s3_sqrt_hz", o.imu.accel_bias_random_walk_m_s3_sqrt_hz);
  imu.Put("gyro_range_rad_s", o.imu.gyro_range_rad_s);
  imu.Put("accel_range_m_s2", o.imu.accel_range_m_s2);
  imu.Put("gravity_m_s2", o.imu.gravity_m_s2);
  imu.Put("noise_inflation", o.imu.noise_inflation);
  YamlSection init(&out, "init");
  init.Put("window_s", o.init.window_s);
  init.Put("accel_std_threshold_m_s2", o.init.accel_std_threshold_m_s2);
  init.Put("gyro_std_threshold_rad_s", o.init.gyro_std_threshold_rad_s);
  init.Put("velocity_sigma_m_s", o.init.velocity_sigma_m_s);
  init.Put("accel_bias_sigma_m_s2", o.init.accel_bias_sigma_m_s2);
  init.Put("gyro_bias_sigma_floor_rad_s", o.init.gyro_bias_sigma_floor_rad_s);
  YamlSection clones(&out, "clones");
  clones.Put("max_clones", o.clones.max_clones);
  clones.Put("max_trigger_lateness_s", o.clones.max_trigger_lateness_s);
  clones.Put("stamp_tolerance_s", o.clones.stamp_tolerance_s);
  YamlSection rp(&out, "relative_pose");
  rp.Put("max_delay_s", o.relative_pose.max_delay_s);
  rp.Put("gate_probability", o.relative_pose.gate_probability);
  rp.Put("covariance_inflation", o.relative_pose.covariance_inflation);
  const WheelOdometryOptions& w = o.wheels;
  YamlSection wheels(&out, "wheels");
  wheels.Put("enabled", w.enabled);
  wheels.Put("wheel_radius_m", w.wheel_radius_m);
  wheels.Put("track_m", w.track_m);
  wheels.Put("yaw_scrub_factor", w.yaw_scrub_factor);
  wheels.Put("lever_arm_body_m", w.lever_arm_body_m);
  wheels.Put("nonholonomic_point_body_m", w.nonholonomic_point_body_m);
  wheels.Put("slip_ratio_base", w.slip_ratio_base);
  wheels.Put("slip_ratio_per_tilt_rad", w.slip_ratio_per_tilt_rad);
  wheels.Put("update_period_s", w.update_period_s);
  wheels.Put("forward_sigma_m_s", w.forward_sigma_m_s);
  wheels.Put("forward_sigma_per_speed", w.forward_sigma_per_speed);
  wheels.Put("slip_sigma_gain", w.slip_sigma_gain);
  wheels.Put("use_nonholonomic", w.use_nonholonomic);
  wheels.Put("lateral_sigma_m_s", w.lateral_sigma_m_s);
  wheels.Put("use_yaw_rate", w.use_yaw_rate);
  wheels.Put("yaw_rate_sigma_rad_s", w.yaw_rate_sigma_rad_s);
  wheels.Put("max_delay_s", w.max_delay_s);
  wheels.Put("gate_probability", w.gate_probability);
  YamlSection zupt(&out, "zupt");
  zupt.Put("enabled", o.zupt.enabled);
  zupt.Put("window_s", o.zupt.window_s);
  zupt.Put("wheel_rate_threshold_rad_s", o.zupt.wheel_rate_threshold_rad_s);
  zupt.Put("gyro_threshold_rad_s", o.zupt.gyro_threshold_rad_s);
  zupt.Put("accel_std_threshold_m_s2", o.zupt.accel_std_threshold_m_s2);
  zupt.Put("allow_imu_only", o.zupt.allow_imu_only);
  zupt.Put("velocity_sigma_m_s", o.zupt.velocity_sigma_m_s);
  zupt.Put("period_s", o.zupt.period_s);
  YamlSection health(&out, "health");
  health.Put("max_imu_gap_s", o.health.max_imu_gap_s);
  health.Put("recovery_s", o.health.recovery_s);
  health.Put("aiding_timeout_s", o.health.aiding_timeout_s);
  return out;
}

}  // namespace rover::estimator
