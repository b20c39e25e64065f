// EskfOptions: YAML round trip (logs carry the options for replay) and
// errors that name the key.

#include <gtest/gtest.h>

#include <random>

#include "core/config/config.h"
#include "estimator/eskf/eskf_options.h"

namespace rover::estimator {
namespace {

// Options with every value changed to something a default would not give,
// including numbers that need all 17 digits.
EskfOptions Unusual(uint64_t seed) {
  std::mt19937_64 rng(seed);
  const auto r = [&](double lo, double hi) {
    return std::uniform_real_distribution<double>(lo, hi)(rng);
  };
  EskfOptions o;
  o.imu.rate_hz = r(100, 1000);
  o.imu.gyro_noise_density_rad_s_sqrt_hz = r(1e-5, 1e-3);
  o.imu.accel_bias_random_walk_m_s3_sqrt_hz = r(1e-6, 1e-3);
  o.imu.gravity_m_s2 = r(9.7, 9.9);
  o.init.window_s = r(0.5, 2.0);
  o.clones.max_clones = 8;
  o.clones.stamp_tolerance_s = r(1e-5, 1e-3);
  o.relative_pose.gate_probability = r(0.9, 0.9999);
  o.wheels.enabled = false;
  o.wheels.lever_arm_body_m = {r(-1, 1), r(-1, 1), r(-1, 1)};
  o.wheels.nonholonomic_point_body_m = {r(-1, 1), r(-1, 1), r(-1, 1)};
  o.wheels.use_yaw_rate = true;
  o.wheels.slip_ratio_per_tilt_rad = r(0, 0.5);
  o.zupt.allow_imu_only = true;
  o.zupt.period_s = r(0.25, 1.0);
  o.health.aiding_timeout_s = r(1, 5);
  return o;
}

TEST(EskfOptionsTest, YamlRoundTripIsExact) {
  for (uint64_t seed = 1; seed <= 20; ++seed) {
    const EskfOptions o = Unusual(seed);
    const std::string yaml = ToYaml(o);
    const ConfigNode root = ConfigNode::LoadString(yaml, "options.yaml");
    const EskfOptions back = EskfOptions::Load(root);
    EXPECT_NO_THROW(root.CheckNoUnknownKeysRecursive());
    EXPECT_TRUE(back == o) << yaml;
  }
  EXPECT_TRUE(EskfOptions::Load(ConfigNode::LoadString(ToYaml(EskfOptions{}), "d")) ==
              EskfOptions{});
}

TEST(EskfOptionsTest, OneChangedValueIsNotEqual) {
  EskfOptions a, b;
  b.wheels.lever_arm_body_m.z() += 1e-12;
  EXPECT_FALSE(a == b);
}

}  // namespace
}  // namespace rover::estimator
