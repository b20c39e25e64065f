#include "hil/sim/sensors/imu_model.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <set>
#include <string>
#include <vector>

#include "hil/sim/analytic_trajectory.h"

namespace rover::sim {
namespace {

using ::testing::HasSubstr;

std::string ConfigPath(const std::string& name) {
  const char* source = std::getenv("ROVER_SOURCE_DIR");
  return std::string(source != nullptr ? source : ".") + "/hil/config/" + name;
}

std::string ReadFile(const std::string& path) {
  std::ifstream in(path);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

std::string WriteTemp(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + name;
  std::ofstream(path) << text;
  return path;
}

// A motion source that holds still with a constant rate and specific force.
class ConstantMotion : public MotionSource {
 public:
  ConstantMotion(const Eigen::Vector3d& omega, const Eigen::Vector3d& f) : omega_(omega), f_(f) {}
  TrajectorySample Evaluate(double t_s) const override {
    TrajectorySample s;
    s.t_s = t_s;
    s.omega_body_rad_s = omega_;
    s.specific_force_body_m_s2 = f_;
    return s;
  }

 private:
  Eigen::Vector3d omega_, f_;
};

// A rate that equals the evaluation time: shows where truth was sampled.
class RampMotion : public MotionSource {
 public:
  TrajectorySample Evaluate(double t_s) const override {
    TrajectorySample s;
    s.t_s = t_s;
    s.omega_body_rad_s = {t_s, 0.0, 0.0};
    return s;
  }
};

ImuModelOptions Ideal400() {
  ImuModelOptions o;
  o.rate_hz = 400.0;
  return o;
}

TEST(ImuModelOptionsTest, ShippedConfigsLoad) {
  const ImuModelOptions mti = ImuModelOptions::LoadFile(ConfigPath("imu_mti10.yaml"));
  EXPECT_EQ(mti.model, "Xsens MTi-10 class");
  EXPECT_EQ(mti.rate_hz, 400.0);
  EXPECT_NEAR(mti.gyro.noise_density, 0.01 * M_PI / 180.0, 1e-6);
  EXPECT_NEAR(mti.accel.noise_density, 60e-6 * 9.80665, 1e-6);
  EXPECT_NEAR(mti.gyro.range, 450.0 * M_PI / 180.0, 1e-3);
  EXPECT_NEAR(mti.gyro.scale_factor_error.x(), 120e-6, 1e-15);
  const ImuModelOptions adis = ImuModelOptions::LoadFile(ConfigPath("imu_adis16448.yaml"));
  EXPECT_EQ(adis.model, "ADIS16448 class");
  EXPECT_NEAR(adis.gyro.quantization_per_lsb, 0.04 * M_PI / 180.0, 1e-6);
  EXPECT_NEAR(adis.accel.quantization_per_lsb, 9.80665 / 1200.0, 1e-5);
  EXPECT_NEAR(adis.gyro.range, 1000.0 * M_PI / 180.0, 1e-3);
}

TEST(ImuModelOptionsTest, UnknownKeyIsNamedWithFileAndLine) {
  std::string text = ReadFile(ConfigPath("imu_mti10.yaml"));
  ASSERT_FALSE(text.empty());
  text = "gyro_noise_density_deg_s_sqrt_hz: 0.01\n" + text;
  const std::string path = WriteTemp("imu_unknown.yaml", text);
  try {
    ImuModelOptions::LoadFile(path);
    FAIL() << "expected a ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_THAT(e.what(), HasSubstr(path + ":1"));
    EXPECT_THAT(e.what(), HasSubstr("gyro_noise_density_deg_s_sqrt_hz"));
  }
}

TEST(ImuModelOptionsTest, OutOfRangeIsNamedWithFileAndLine) {
  std::string text = ReadFile(ConfigPath("imu_mti10.yaml"));
  const std::size_t at = text.find("rate_hz: 400.0");
  ASSERT_NE(at, std::string::npos);
  text.replace(at, 14, "rate_hz: 5000");
  const int line =
      1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<long>(at), '\n'));
  const std::string path = WriteTemp("imu_range.yaml", text);
  try {
    ImuModelOptions::LoadFile(path);
    FAIL() << "expected a ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_THAT(e.what(), HasSubstr(path + ":" + std::to_string(line) + ": rate_hz"));
    EXPECT_THAT(e.what(), HasSubstr("[100, 1000]"));
    EXPECT_THAT(e.what(), HasSubstr("5000"));
  }
}

TEST(ImuModelOptionsTest, RejectsBadMisalignmentAndMissingKeys) {
  std::string text = ReadFile(ConfigPath("imu_mti10.yaml"));
  const std::size_t at = text.find("  - [0.0, 3.0e-4, -5.0e-4]");
  ASSERT_NE(at, std::string::npos);
  std::string bad = text;
  bad.replace(at, 26, "  - [0.1, 3.0e-4, -5.0e-4]");
  EXPECT_THROW(ImuModelOptions::LoadFile(WriteTemp("imu_diag.yaml", bad)), ConfigError);
  std::string missing = text;
  const std::size_t seed = missing.find("seed: 1\n");
  missing.erase(seed, 8);
  try {
    ImuModelOptions::LoadFile(WriteTemp("imu_missing.yaml", missing));
    FAIL() << "expected a ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_THAT(e.what(), HasSubstr("seed"));
  }
}

TEST(ImuModelTest, IdealModelReproducesTruthAtNominalTimes) {
  const AnalyticTrajectory motion(AnalyticTrajectoryOptions{});
  const Time start = Time::FromNanoseconds(5'000'000'000);
  ImuModel imu(Ideal400(), start);
  for (uint64_t k = 0; k < 100; ++k) {
    TrajectorySample truth;
    const drivers::ImuSample m = imu.Next(motion, &truth);
    EXPECT_EQ(m.sequence, k);
    EXPECT_EQ(m.stamp, start + Duration::Nanoseconds(static_cast<int64_t>(k) * 2'500'000));
    EXPECT_DOUBLE_EQ(truth.t_s, static_cast<double>(k) * 0.0025);
    EXPECT_EQ(m.angular_velocity_rad_s, truth.omega_body_rad_s);
    EXPECT_EQ(m.linear_acceleration_m_s2, truth.specific_force_body_m_s2);
  }
}

TEST(ImuModelTest, NonIntegerNanosecondPeriodDoesNotDrift) {
  ImuModelOptions o = Ideal400();
  o.rate_hz = 409.6;
  const ImuModel imu(o, Time::Zero());
  EXPECT_EQ(imu.NominalSampleTime(4096).nanoseconds(), 10'000'000'000);
}

// Discrete white noise has sigma = density * sqrt(rate).
TEST(ImuModelTest, WhiteNoiseMatchesDensities) {
  ImuModelOptions o = Ideal400();
  o.gyro.noise_density = 1.745e-4;
  o.accel.noise_density = 5.88e-4;
  ImuModel imu(o, Time::Zero());
  const int n = 200000;
  Eigen::Array3d sum_g = Eigen::Array3d::Zero(), sq_g = sum_g, sum_a = sum_g, sq_a = sum_g;
  const Eigen::Vector3d g(0, 0, 9.80665);
  for (int i = 0; i < n; ++i) {
    const drivers::ImuSample m = imu.Corrupt(Time::Zero(), Eigen::Vector3d::Zero(), g);
    sum_g += m.angular_velocity_rad_s.array();
    sq_g += m.angular_velocity_rad_s.array().square();
    const Eigen::Array3d a = (m.linear_acceleration_m_s2 - g).array();
    sum_a += a;
    sq_a += a.square();
  }
  const double sigma_g = o.gyro.noise_density * std::sqrt(o.rate_hz);
  const double sigma_a = o.accel.noise_density * std::sqrt(o.rate_hz);
  for (int axis = 0; axis < 3; ++axis) {
    const double mean_g = sum_g[axis] / n, mean_a = sum_a[axis] / n;
    EXPECT_NEAR(std::sqrt(sq_g[axis] / n - mean_g * mean_g) / sigma_g, 1.0, 0.01);
    EXPECT_NEAR(std::sqrt(sq_a[axis] / n - mean_a * mean_a) / sigma_a, 1.0, 0.01);
    EXPECT_NEAR(mean_g, 0.0, 4.0 * sigma_g / std::sqrt(n));
    EXPECT_NEAR(mean_a, 0.0, 4.0 * sigma_a / std::sqrt(n));
  }
}

// After T seconds the random-walk bias has variance K^2 T; the turn-on bias
// has the configured sigma. Checked over many seeds (independent units).
TEST(ImuModelTest, BiasRandomWalkAndTurnOnBiasMatchTheirSigmas) {
  ImuModelOptions o = Ideal400();
  o.gyro.bias_random_walk = 1.5e-5;
  o.accel.turn_on_bias_sigma = 0.03;
  const int units = 400, samples = 4000;  // 10 s each
  double sum_sq_walk = 0.0, sum_sq_turn_on = 0.0;
  for (int unit = 0; unit < units; ++unit) {
    o.seed = static_cast<uint64_t>(1000 + unit);
    ImuModel imu(o, Time::Zero());
    sum_sq_turn_on += imu.accel_bias_m_s2().squaredNorm();
    for (int i = 0; i < samples; ++i) imu.Corrupt(Time::Zero(), Eigen::Vector3d::Zero(), {});
    sum_sq_walk += imu.gyro_bias_rad_s().squaredNorm();
  }
  const double walk_var = sum_sq_walk / (3.0 * units);
  const double expected_walk_var = o.gyro.bias_random_walk * o.gyro.bias_random_walk * 10.0;
  EXPECT_NEAR(walk_var / expected_walk_var, 1.0, 0.15);
  EXPECT_NEAR(std::sqrt(sum_sq_turn_on / (3.0 * units)) / 0.03, 1.0, 0.08);
}

TEST(ImuModelTest, ScaleFactorAndMisalignment) {
  ImuModelOptions o = Ideal400();
  o.gyro.scale_factor_error = {1e-3, -2e-3, 3e-3};
  o.gyro.misalignment_rad << 0, 1e-3, 0, 2e-3, 0, -1e-3, 0, 4e-3, 0;
  ImuModel imu(o, Time::Zero());
  const Eigen::Vector3d w = imu.Corrupt(Time::Zero(), {1.0, 0.0, 0.0}, {}).angular_velocity_rad_s;
  EXPECT_NEAR(w.x(), 1.001, 1e-15);
  EXPECT_NEAR(w.y(), 2e-3 * 0.998, 1e-15);
  EXPECT_NEAR(w.z(), 0.0, 1e-15);
  const Eigen::Vector3d w2 = imu.Corrupt(Time::Zero(), {0.0, 1.0, 0.0}, {}).angular_velocity_rad_s;
  EXPECT_NEAR(w2.x(), 1e-3 * 1.001, 1e-15);
  EXPECT_NEAR(w2.y(), 0.998, 1e-15);
  EXPECT_NEAR(w2.z(), 4e-3 * 1.003, 1e-15);
}

TEST(ImuModelTest, SaturationClips) {
  ImuModelOptions o = Ideal400();
  o.gyro.range = 7.854;
  o.accel.range = 156.9;
  ImuModel imu(o, Time::Zero());
  const drivers::ImuSample m = imu.Corrupt(Time::Zero(), {20.0, -20.0, 1.0}, {0, 0, -400.0});
  EXPECT_EQ(m.angular_velocity_rad_s, Eigen::Vector3d(7.854, -7.854, 1.0));
  EXPECT_EQ(m.linear_acceleration_m_s2, Eigen::Vector3d(0, 0, -156.9));
}

TEST(ImuModelTest, QuantisationStepIsVisible) {
  ImuModelOptions o = Ideal400();
  o.gyro.quantization_per_lsb = 6.981e-4;
  o.accel.quantization_per_lsb = 8.172e-3;
  ImuModel imu(o, Time::Zero());
  std::set<double> levels;
  for (int i = 0; i < 1000; ++i) {
    // A slow ramp over ten LSBs: the output moves in whole steps only.
    const double x = 1e-5 * i;
    const drivers::ImuSample m = imu.Corrupt(Time::Zero(), {x, 0, 0}, {0, 0, 9.80665});
    const double lsb = m.angular_velocity_rad_s.x() / o.gyro.quantization_per_lsb;
    EXPECT_NEAR(lsb, std::round(lsb), 1e-9);
    EXPECT_LE(std::abs(m.angular_velocity_rad_s.x() - x),
              0.5 * o.gyro.quantization_per_lsb + 1e-15);
    const double a_lsb = m.linear_acceleration_m_s2.z() / o.accel.quantization_per_lsb;
    EXPECT_NEAR(a_lsb, std::round(a_lsb), 1e-9);
    levels.insert(m.angular_velocity_rad_s.x());
  }
  EXPECT_EQ(levels.size(), 15u);  // 0 .. 0.00999 rad/s in 6.981e-4 steps
}

// The stamp carries the jitter and truth is evaluated at exactly the stamp.
TEST(ImuModelTest, SampleTimeJitter) {
  ImuModelOptions o = Ideal400();
  o.sample_time_jitter_sigma_s = 20e-6;
  const Time start = Time::FromNanoseconds(1'000'000'000);
  ImuModel imu(o, start);
  const RampMotion ramp;
  const int n = 20000;
  double sum_sq = 0.0;
  Time previous = Time::Zero();
  for (int k = 0; k < n; ++k) {
    const drivers::ImuSample m = imu.Next(ramp);
    const double jitter_s = (m.stamp - imu.NominalSampleTime(static_cast<uint64_t>(k))).ToSeconds();
    sum_sq += jitter_s * jitter_s;
    EXPECT_EQ(m.angular_velocity_rad_s.x(), (m.stamp - start).ToSeconds());
    EXPECT_GT(m.stamp, previous);
    previous = m.stamp;
  }
  EXPECT_NEAR(std::sqrt(sum_sq / n) / 20e-6, 1.0, 0.03);
}

TEST(ImuModelTest, DeterministicPerSeedAndPerSource) {
  const ImuModelOptions mti = ImuModelOptions::LoadFile(ConfigPath("imu_mti10.yaml"));
  const AnalyticTrajectory motion(AnalyticTrajectoryOptions{});
  ImuModel a(mti, Time::Zero()), b(mti, Time::Zero());
  ImuModelOptions other = mti;
  other.seed = 2;
  ImuModel c(other, Time::Zero());
  bool differs = false;
  for (int i = 0; i < 1000; ++i) {
    const drivers::ImuSample ma = a.Next(motion), mb = b.Next(motion), mc = c.Next(motion);
    ASSERT_EQ(ma.stamp, mb.stamp);
    ASSERT_EQ(ma.angular_velocity_rad_s, mb.angular_velocity_rad_s);
    ASSERT_EQ(ma.linear_acceleration_m_s2, mb.linear_acceleration_m_s2);
    differs |= ma.angular_velocity_rad_s != mc.angular_velocity_rad_s;
  }
  EXPECT_TRUE(differs);

  // Each error source has its own stream: switching the jitter off changes
  // the stamps but not the noise (the motion here does not depend on time).
  ImuModelOptions no_jitter = mti;
  no_jitter.sample_time_jitter_sigma_s = 0.0;
  const ConstantMotion still({0.1, 0.2, 0.3}, {0.0, 0.0, 9.8});
  ImuModel with(mti, Time::Zero()), without(no_jitter, Time::Zero());
  bool stamps_differ = false;
  for (int i = 0; i < 1000; ++i) {
    const drivers::ImuSample mw = with.Next(still), mo = without.Next(still);
    stamps_differ |= mw.stamp != mo.stamp;
    ASSERT_EQ(mw.angular_velocity_rad_s, mo.angular_velocity_rad_s);
    ASSERT_EQ(mw.linear_acceleration_m_s2, mo.linear_acceleration_m_s2);
  }
  EXPECT_TRUE(stamps_differ);
}

}  // namespace
}  // namespace rover::sim
