#ifndef ROVER_ESTIMATOR_ESKF_ESKF_OPTIONS_H_
#define ROVER_ESTIMATOR_ESKF_ESKF_OPTIONS_H_

// Options of the local reference filter, one struct per component, loaded
// from the `estimator` section of a board profile. Every key is optional and
// defaults to the value below (an MTi-10-class IMU on the rover); ranges are
// checked on load and unknown keys are errors (CheckNoUnknownKeysRecursive).

#include <Eigen/Core>

#include "core/config/config.h"

namespace rover::estimator {

/// The IMU's error model, from its datasheet (continuous-time densities).
struct ImuNoiseOptions {
  double rate_hz = 400.0;  ///< nominal sample rate
  double gyro_noise_density_rad_s_sqrt_hz = 1.745e-4;
  double gyro_bias_random_walk_rad_s2_sqrt_hz = 1.51e-5;
  double accel_noise_density_m_s2_sqrt_hz = 5.88e-4;
  double accel_bias_random_walk_m_s3_sqrt_hz = 2.55e-5;
  double gyro_range_rad_s = 7.854;  ///< readings at or beyond this are saturated
  double accel_range_m_s2 = 156.9;  ///< readings at or beyond this are saturated
  double gravity_m_s2 = 9.80665;    ///< local gravity magnitude
  /// Inflates the white-noise densities for errors the model leaves out
  /// (scale factor, misalignment, vibration); 1 means datasheet values.
  double noise_inflation = 1.0;

  static ImuNoiseOptions Load(const ConfigNode& node);
  friend bool operator==(const ImuNoiseOptions&, const ImuNoiseOptions&) = default;
};

/// Static initialisation: standstill detection and the initial covariance.
struct InitOptions {
  double window_s = 1.0;                      ///< standstill window before the filter starts
  double accel_std_threshold_m_s2 = 0.05;     ///< per-axis std of the specific force
  double gyro_std_threshold_rad_s = 0.01;     ///< per-axis std of the angular rate
  double velocity_sigma_m_s = 0.01;           ///< at standstill
  double accel_bias_sigma_m_s2 = 0.03;        ///< turn-on bias repeatability
  double gyro_bias_sigma_floor_rad_s = 2e-4;  ///< added to the window-mean uncertainty

  static InitOptions Load(const ConfigNode& node);
  friend bool operator==(const InitOptions&, const InitOptions&) = default;
};

/// Stochastic cloning.
struct CloneOptions {
  int max_clones = 6;  ///< clones kept with full cross-covariance (VO keeps 5 keyframes)
  /// A trigger this much older than the newest IMU sample is still cloned, by
  /// extrapolating the pose back; older ones are rejected.
  double max_trigger_lateness_s = 0.02;
  /// Capture times in relative-pose measurements match clone stamps within this.
  double stamp_tolerance_s = 1e-4;

  static CloneOptions Load(const ConfigNode& node);
  friend bool operator==(const CloneOptions&, const CloneOptions&) = default;
};

/// Delayed relative-pose (VO) updates.
struct RelativePoseOptions {
  double max_delay_s = 0.5;           ///< measurements later than this after to_stamp are refused
  double gate_probability = 0.999;    ///< chi-square gate (6 dof)
  double covariance_inflation = 1.0;  ///< scales the stated covariance

  static RelativePoseOptions Load(const ConfigNode& node);
  friend bool operator==(const RelativePoseOptions&, const RelativePoseOptions&) = default;
};

/// Wheel odometry: body-frame forward (and lateral) velocity from four wheels.
struct WheelOdometryOptions {
  bool enabled = true;
  double wheel_radius_m = 0.1;
  double track_m = 0.5;           ///< left to right wheel centre
  double yaw_scrub_factor = 1.3;  ///< skid steer: wheel-speed difference / ideal
  /// Position of the wheel-axle centre (the point whose forward velocity the
  /// wheels measure) in the body frame.
  Eigen::Vector3d lever_arm_body_m{0.0, 0.0, -0.25};
  /// The point with no sideways velocity for the non-holonomic constraint,
  /// in the body frame: the centre of the wheel contacts on a real rover.
  Eigen::Vector3d nonholonomic_point_body_m{0.0, 0.0, -0.35};
  /// Expected longitudinal slip s = base + per_tilt * tilt (tilt: angle of
  /// the body z axis from vertical), from a wheel-terrain calibration; the
  /// wheel speed is scaled by (1 - s) before the update. 0: no compensation.
  double slip_ratio_base = 0.0;
  double slip_ratio_per_tilt_rad = 0.0;
  double update_period_s = 0.1;           ///< wheel readings are averaged over this period
  double forward_sigma_m_s = 0.01;        ///< at zero speed
  double forward_sigma_per_speed = 0.03;  ///< grows with |speed| (unmodelled slip ratio)
  /// Grows with the estimated slip: the disagreement between front and rear
  /// wheels of a side (m/s per m/s of disagreement).
  double slip_sigma_gain = 2.0;
  bool use_nonholonomic = true;  ///< lateral velocity measured as zero
  double lateral_sigma_m_s = 0.02;
  bool use_yaw_rate = false;  ///< yaw rate from the left-right difference
  double yaw_rate_sigma_rad_s = 0.02;
  double max_delay_s = 0.05;
  double gate_probability = 0.999;

  static WheelOdometryOptions Load(const ConfigNode& node);
  friend bool operator==(const WheelOdometryOptions&, const WheelOdometryOptions&) = default;
};

/// Zero-velocity updates at standstill.
struct ZuptOptions {
  bool enabled = true;
  double window_s = 0.25;                    ///< detection window
  double wheel_rate_threshold_rad_s = 0.01;  ///< every wheel slower than this
  double gyro_threshold_rad_s = 0.01;        ///< |mean bias-corrected rate| below this
  double accel_std_threshold_m_s2 = 0.05;    ///< per-axis std below this
  /// Without wheel readings, detect standstill from the IMU alone. Off by
  /// default: a rover cruising straight on flat ground looks static to an IMU.
  bool allow_imu_only = false;
  double velocity_sigma_m_s = 0.005;
  double period_s =
      0.25;  ///< one update per period while standing (>= window: independent windows)

  static ZuptOptions Load(const ConfigNode& node);
  friend bool operator==(const ZuptOptions&, const ZuptOptions&) = default;
};

/// Bad-input handling and health.
struct EskfHealthOptions {
  double max_imu_gap_s = 0.05;    ///< longer intervals set kStatusImuGap
  double recovery_s = 0.5;        ///< flags clear after this long without new trouble
  double aiding_timeout_s = 2.0;  ///< kStatusNoAiding after this long without aiding

  static EskfHealthOptions Load(const ConfigNode& node);
  friend bool operator==(const EskfHealthOptions&, const EskfHealthOptions&) = default;
};

/// Everything the local reference filter needs.
struct EskfOptions {
  ImuNoiseOptions imu;
  InitOptions init;
  CloneOptions clones;
  RelativePoseOptions relative_pose;
  WheelOdometryOptions wheels;
  ZuptOptions zupt;
  EskfHealthOptions health;

  /// Reads the optional sections imu, init, clones, relative_pose, wheels,
  /// zupt and health of `node`. Throws ConfigError (file:line, key, expected,
  /// found) for wrong types or out-of-range values.
  static EskfOptions Load(const ConfigNode& node);
  /// Loads a whole file whose top level is the estimator section and rejects
  /// unknown keys.
  static EskfOptions LoadFile(const std::string& path);

  friend bool operator==(const EskfOptions&, const EskfOptions&) = default;
};

/// The options as YAML text that Load() reads back to equal options: every
/// key is written, numbers with 17 significant digits (exact round trip).
/// Logs carry it, so that a replay runs the filter with the same options.
std::string ToYaml(const EskfOptions& options);

/// Largest supported CloneOptions::max_clones (fixed-size storage).
inline constexpr int kMaxClones = 8;

}  // namespace rover::estimator

#endif  // ROVER_ESTIMATOR_ESKF_ESKF_OPTIONS_H_
