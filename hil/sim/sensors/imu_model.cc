#include "hil/sim/sensors/imu_model.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "hil/sim/seed.h"

namespace rover::sim {
namespace {

enum Stream : uint64_t { kGyroNoise = 1, kAccelNoise, kGyroWalk, kAccelWalk, kJitter, kTurnOn };

// Key suffixes and plausible ranges of one triad in the YAML file.
struct TriadKeys {
  const char* prefix;           // "gyro" / "accel"
  const char* unit;             // "rad_s" / "m_s2"
  const char* walk_unit;        // "rad_s2" / "m_s3"
  double max_noise_density;     // x / sqrt(Hz)
  double max_bias_random_walk;  // x / sqrt(s)
  double max_turn_on_bias;      // x
  double max_quantization;      // x per LSB
  double min_range, max_range;  // x
};

std::string Key(const TriadKeys& k, const std::string& name) {
  return std::string(k.prefix) + "_" + name;
}

ImuTriadErrors LoadTriad(const ConfigNode& node, const TriadKeys& k) {
  const std::string unit = k.unit;
  ImuTriadErrors e;
  e.noise_density = node.GetInRange<double>(Key(k, "noise_density_" + unit + "_sqrt_hz"), 0.0,
                                            k.max_noise_density);
  e.bias_random_walk =
      node.GetInRange<double>(Key(k, "bias_random_walk_" + std::string(k.walk_unit) + "_sqrt_hz"),
                              0.0, k.max_bias_random_walk);
  e.turn_on_bias_sigma =
      node.GetInRange<double>(Key(k, "turn_on_bias_sigma_" + unit), 0.0, k.max_turn_on_bias);

  const std::string scale_key = Key(k, "scale_factor_error_ppm");
  const Eigen::Vector3d scale_ppm = node.Get<Eigen::Vector3d>(scale_key);
  if (!(scale_ppm.cwiseAbs().maxCoeff() <= 1e5)) {
    node.Fail(scale_key, "every axis must be within +-100000 ppm (10 %)");
  }
  e.scale_factor_error = 1e-6 * scale_ppm;

  const std::string misalignment_key = Key(k, "misalignment_rad");
  e.misalignment_rad = node.Get<Eigen::Matrix3d>(misalignment_key);
  if (e.misalignment_rad.diagonal().cwiseAbs().maxCoeff() != 0.0) {
    node.Fail(misalignment_key, "the diagonal must be 0 (it holds tilts between axes only)");
  }
  if (!(e.misalignment_rad.cwiseAbs().maxCoeff() <= 0.1)) {
    node.Fail(misalignment_key, "misalignment angles must be small, |angle| <= 0.1 rad");
  }
  e.quantization_per_lsb =
      node.GetInRange<double>(Key(k, "quantization_" + unit + "_per_lsb"), 0.0, k.max_quantization);
  e.range = node.GetInRange<double>(Key(k, "range_" + unit), k.min_range, k.max_range);
  return e;
}

constexpr TriadKeys kGyroKeys{"gyro", "rad_s", "rad_s2", 0.1, 0.01, 0.5, 0.1, 0.5, 100.0};
// The accelerometer must at least measure gravity at rest, hence >= 10 m/s^2.
constexpr TriadKeys kAccelKeys{"accel", "m_s2", "m_s3", 1.0, 0.1, 2.0, 1.0, 10.0, 2000.0};

}  // namespace

ImuModelOptions ImuModelOptions::Load(const ConfigNode& node) {
  ImuModelOptions o;
  o.model = node.Get<std::string>("model", "unnamed");
  o.rate_hz = node.GetInRange<double>("rate_hz", 100.0, 1000.0);
  // Beyond a tenth of the period the jitter would reorder samples.
  o.sample_time_jitter_sigma_s =
      node.GetInRange<double>("sample_time_jitter_sigma_s", 0.0, 0.1 / o.rate_hz);
  o.seed = node.Get<uint64_t>("seed");
  o.gyro = LoadTriad(node, kGyroKeys);
  o.accel = LoadTriad(node, kAccelKeys);
  return o;
}

ImuModelOptions ImuModelOptions::LoadFile(const std::string& path) {
  const ConfigNode root = ConfigNode::LoadFile(path);
  ImuModelOptions o = Load(root);
  root.CheckNoUnknownKeysRecursive();
  return o;
}

calib::ImuCalibration ImuCalibrationOf(const ImuModelOptions& options) {
  calib::ImuCalibration c;
  c.rate_hz = options.rate_hz;
  c.gyro_noise_density_rad_s_sqrt_hz = options.gyro.noise_density;
  c.gyro_random_walk_rad_s2_sqrt_hz = options.gyro.bias_random_walk;
  c.accel_noise_density_m_s2_sqrt_hz = options.accel.noise_density;
  c.accel_random_walk_m_s3_sqrt_hz = options.accel.bias_random_walk;
  return c;
}

ImuModelOptions ImuModelOptions::Ideal() const {
  ImuModelOptions o;
  o.model = "ideal";
  o.rate_hz = rate_hz;
  o.seed = seed;
  return o;
}

Eigen::Vector3d ImuModel::GaussianStream::Draw3(double sigma) {
  // Fixed draw order x, y, z so the stream never depends on evaluation order.
  const double x = Draw();
  const double y = Draw();
  const double z = Draw();
  return sigma * Eigen::Vector3d(x, y, z);
}

ImuModel::ImuModel(const ImuModelOptions& options, Time start)
    : options_(options),
      start_(start),
      gyro_noise_(StreamSeed(options.seed, kGyroNoise)),
      accel_noise_(StreamSeed(options.seed, kAccelNoise)),
      gyro_walk_(StreamSeed(options.seed, kGyroWalk)),
      accel_walk_(StreamSeed(options.seed, kAccelWalk)),
      jitter_(StreamSeed(options.seed, kJitter)) {
  GaussianStream turn_on(StreamSeed(options.seed, kTurnOn));
  gyro_bias_rad_s_ = turn_on.Draw3(options_.gyro.turn_on_bias_sigma);
  accel_bias_m_s2_ = turn_on.Draw3(options_.accel.turn_on_bias_sigma);
}

Time ImuModel::NominalSampleTime(uint64_t k) const {
  // From the sample index, not by accumulation, so rates like 819.2 Hz whose
  // period is not a whole number of nanoseconds do not drift.
  return start_ +
         Duration::Nanoseconds(std::llround(static_cast<double>(k) * 1e9 / options_.rate_hz));
}

drivers::ImuSample ImuModel::Next(const MotionSource& motion, TrajectorySample* truth) {
  const Time nominal = NominalSampleTime(next_index_);
  double jitter_s = 0.0;
  if (options_.sample_time_jitter_sigma_s > 0.0) {
    const double limit = 0.25 * period_s();  // keeps samples in order
    jitter_s = std::clamp(options_.sample_time_jitter_sigma_s * jitter_.Draw(), -limit, limit);
  }
  // The stamp is on the nanosecond clock; truth is evaluated at exactly it.
  const Time stamp = nominal + Duration::FromSeconds(jitter_s);
  const TrajectorySample sample = motion.Evaluate((stamp - start_).ToSeconds());
  if (truth != nullptr) *truth = sample;
  return Corrupt(stamp, sample.omega_body_rad_s, sample.specific_force_body_m_s2);
}

Eigen::Vector3d ImuModel::Apply(const ImuTriadErrors& e, const Eigen::Vector3d& truth,
                                const Eigen::Vector3d& bias, const Eigen::Vector3d& noise) {
  const Eigen::Matrix3d gain = (Eigen::Vector3d::Ones() + e.scale_factor_error).asDiagonal() *
                               (Eigen::Matrix3d::Identity() + e.misalignment_rad);
  Eigen::Vector3d y = gain * truth + bias + noise;
  if (e.quantization_per_lsb > 0.0) {
    y = (y / e.quantization_per_lsb).array().round().matrix() * e.quantization_per_lsb;
  }
  return y.cwiseMax(-e.range).cwiseMin(e.range);
}

drivers::ImuSample ImuModel::Corrupt(Time stamp, const Eigen::Vector3d& omega_true_rad_s,
                                     const Eigen::Vector3d& specific_force_true_m_s2) {
  const double sqrt_dt = std::sqrt(period_s());
  // Discrete equivalents of the densities: white noise sigma = N / sqrt(dt),
  // random-walk step sigma = K * sqrt(dt).
  gyro_bias_rad_s_ += gyro_walk_.Draw3(options_.gyro.bias_random_walk * sqrt_dt);
  accel_bias_m_s2_ += accel_walk_.Draw3(options_.accel.bias_random_walk * sqrt_dt);
  drivers::ImuSample out;
  out.stamp = stamp;
  out.sequence = next_index_++;
  out.angular_velocity_rad_s = Apply(options_.gyro, omega_true_rad_s, gyro_bias_rad_s_,
                                     gyro_noise_.Draw3(options_.gyro.noise_density / sqrt_dt));
  out.linear_acceleration_m_s2 = Apply(options_.accel, specific_force_true_m_s2, accel_bias_m_s2_,
                                       accel_noise_.Draw3(options_.accel.noise_density / sqrt_dt));
  return out;
}

}  // namespace rover::sim
