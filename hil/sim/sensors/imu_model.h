#ifndef ROVER_HIL_SIM_SENSORS_IMU_MODEL_H_
#define ROVER_HIL_SIM_SENSORS_IMU_MODEL_H_

// A simulated strap-down IMU with the error model of a MEMS datasheet.
//
// Per sample k (nominal time start + k / rate_hz):
//   t_k    = nominal + jitter,              jitter ~ N(0, sample_time_jitter_sigma_s)
//   b     += N(0, bias_random_walk * sqrt(dt))          (rate / acceleration random walk)
//   y      = (I + diag(scale_factor_error)) (I + M) x(t_k) + b + N(0, noise_density / sqrt(dt))
//   y      = clamp(quantise(y), -range, +range)
// where x is the true angular rate (gyro) or specific force (accelerometer)
// in the body (= IMU) frame, evaluated at the jittered time t_k, b starts at
// a turn-on bias drawn once from N(0, turn_on_bias_sigma), M holds the axis
// misalignment (small angles; row i is sensing axis i, entry (i, j) its tilt
// towards body axis j) and dt = 1 / rate_hz. Each error source draws from its
// own seeded stream, so switching one source off leaves the others' draws
// unchanged, and the same options give the same samples bit for bit.

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <random>
#include <string>

#include "core/calib/imu_calibration.h"
#include "core/config/config.h"
#include "core/time/time.h"
#include "drivers/imu/imu_sample.h"
#include "hil/sim/motion/trajectory_sample.h"

namespace rover::sim {

/// Error parameters of one sensor triad (gyroscope or accelerometer). Units
/// are those of the triad's measurement x: rad/s for the gyroscope, m/s^2 for
/// the accelerometer. Defaults are an ideal sensor.
struct ImuTriadErrors {
  double noise_density = 0.0;       ///< x / sqrt(Hz), white noise
  double bias_random_walk = 0.0;    ///< x / sqrt(s): the bias drifts by this * sqrt(t)
  double turn_on_bias_sigma = 0.0;  ///< x, drawn once at construction
  Eigen::Vector3d scale_factor_error = Eigen::Vector3d::Zero();  ///< fraction per axis
  Eigen::Matrix3d misalignment_rad = Eigen::Matrix3d::Zero();    ///< off-diagonal, small
  double quantization_per_lsb = 0.0;                             ///< x per LSB; 0: no quantisation
  double range = std::numeric_limits<double>::infinity();        ///< saturation, +-range
};

struct ImuModelOptions {
  std::string model = "ideal";  ///< description, e.g. "Xsens MTi-10 class"
  double rate_hz = 400.0;
  double sample_time_jitter_sigma_s = 0.0;
  ImuTriadErrors gyro;   ///< rad/s
  ImuTriadErrors accel;  ///< m/s^2
  uint64_t seed = 1;

  /// Loads the options from a map with these keys (all required except
  /// `model`; ranges checked; unknown keys are the caller's
  /// CheckNoUnknownKeys, which LoadFile does):
  ///   model, rate_hz [100, 1000], sample_time_jitter_sigma_s [0, 0.1 / rate_hz], seed,
  ///   gyro_noise_density_rad_s_sqrt_hz, gyro_bias_random_walk_rad_s2_sqrt_hz,
  ///   gyro_turn_on_bias_sigma_rad_s, gyro_scale_factor_error_ppm [x, y, z],
  ///   gyro_misalignment_rad [[0, xy, xz], [yx, 0, yz], [zx, zy, 0]],
  ///   gyro_quantization_rad_s_per_lsb, gyro_range_rad_s,
  ///   accel_noise_density_m_s2_sqrt_hz, accel_bias_random_walk_m_s3_sqrt_hz,
  ///   accel_turn_on_bias_sigma_m_s2, accel_scale_factor_error_ppm,
  ///   accel_misalignment_rad, accel_quantization_m_s2_per_lsb, accel_range_m_s2.
  static ImuModelOptions Load(const ConfigNode& node);
  /// Loads a whole file whose top level is such a map, rejecting unknown keys.
  static ImuModelOptions LoadFile(const std::string& path);
  /// Every error source off (same rate and seed): an ideal IMU.
  ImuModelOptions Ideal() const;
};

/// What a calibration of this simulated IMU would state: its rate and noise
/// densities, mounted at the body origin (the simulator's body is the IMU).
calib::ImuCalibration ImuCalibrationOf(const ImuModelOptions& options);

class ImuModel {
 public:
  /// Sample k is due at start + k / rate_hz (before jitter); the motion
  /// source's time 0 is `start`.
  ImuModel(const ImuModelOptions& options, Time start);

  /// Produces the next sample from `motion`, evaluated at the sample's
  /// jittered time. If `truth` is not null it receives that ground truth.
  drivers::ImuSample Next(const MotionSource& motion, TrajectorySample* truth = nullptr);

  /// Applies the value errors (no timing) to a true rate and specific force
  /// stamped `stamp`, advancing the bias walk by one sample period.
  drivers::ImuSample Corrupt(Time stamp, const Eigen::Vector3d& omega_true_rad_s,
                             const Eigen::Vector3d& specific_force_true_m_s2);

  /// Additive biases applied to the most recent sample (ground truth).
  const Eigen::Vector3d& gyro_bias_rad_s() const { return gyro_bias_rad_s_; }
  const Eigen::Vector3d& accel_bias_m_s2() const { return accel_bias_m_s2_; }
  const ImuModelOptions& options() const { return options_; }
  /// Nominal (unjittered) time of sample k.
  Time NominalSampleTime(uint64_t k) const;
  double period_s() const { return 1.0 / options_.rate_hz; }

 private:
  // One seeded Gaussian stream. Each owns its distribution, because
  // std::normal_distribution caches draws and must not be shared by engines.
  struct GaussianStream {
    explicit GaussianStream(uint64_t seed) : rng(seed) {}
    double Draw() { return normal(rng); }
    Eigen::Vector3d Draw3(double sigma);
    std::mt19937_64 rng;
    std::normal_distribution<double> normal{0.0, 1.0};
  };

  static Eigen::Vector3d Apply(const ImuTriadErrors& e, const Eigen::Vector3d& truth,
                               const Eigen::Vector3d& bias, const Eigen::Vector3d& noise);

  ImuModelOptions options_;
  Time start_;
  uint64_t next_index_ = 0;
  GaussianStream gyro_noise_, accel_noise_, gyro_walk_, accel_walk_, jitter_;
  Eigen::Vector3d gyro_bias_rad_s_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d accel_bias_m_s2_ = Eigen::Vector3d::Zero();
};

}  // namespace rover::sim

#endif  // ROVER_HIL_SIM_SENSORS_IMU_MODEL_H_
