// The one rule from a board's calibration to the filter's and the VO's
// options, as roverd, the simulator and rover-eval vio use it.

#include "estimator/feed/filter_options.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <string>

#include "core/config/config.h"
#include "tests/support/temp_dir.h"

namespace rover::estimator {
namespace {

using ::testing::HasSubstr;

std::string WriteFile(const testing::TempDir& dir, const std::string& name,
                      const std::string& text) {
  const std::string path = dir.File(name).string();
  std::ofstream(path) << text;
  return path;
}

calib::BoardCalibration TestCalibration() {
  calib::BoardCalibration c;
  c.imu.rate_hz = 200.0;
  c.imu.gyro_noise_density_rad_s_sqrt_hz = 1.6968e-4;
  c.imu.gyro_random_walk_rad_s2_sqrt_hz = 1.9393e-5;
  c.imu.accel_noise_density_m_s2_sqrt_hz = 2.0e-3;
  c.imu.accel_random_walk_m_s3_sqrt_hz = 3.0e-3;
  return c;
}

TEST(FilterOptionsFromCalibrationTest, ImuFiguresAndMaxClonesUnderTheFile) {
  const EskfOptions base = FilterOptionsFromCalibration(TestCalibration());
  EXPECT_EQ(base.imu.rate_hz, 200.0);
  EXPECT_EQ(base.imu.gyro_bias_random_walk_rad_s2_sqrt_hz, 1.9393e-5);
  EXPECT_EQ(base.imu.accel_noise_density_m_s2_sqrt_hz, 2.0e-3);
  EXPECT_EQ(base.clones.max_clones, kMaxClones);
  EXPECT_FALSE(base.wheels.enabled);

  testing::TempDir dir;
  const std::string path =
      WriteFile(dir, "filter.yaml", "imu:\n  rate_hz: 100\ninit:\n  window_s: 0.25\n");
  const EskfOptions o = FilterOptionsFromCalibration(TestCalibration(), path);
  EXPECT_EQ(o.imu.rate_hz, 100.0);                               // the file's
  EXPECT_EQ(o.imu.gyro_noise_density_rad_s_sqrt_hz, 1.6968e-4);  // the calibration's
  EXPECT_EQ(o.init.window_s, 0.25);
  EXPECT_EQ(o.clones.max_clones, kMaxClones);
}

TEST(FilterOptionsFromCalibrationTest, NonPositiveFiguresKeepTheDefaults) {
  calib::BoardCalibration c = TestCalibration();
  c.imu.rate_hz = 0.0;
  c.imu.accel_random_walk_m_s3_sqrt_hz = -1.0;
  const EskfOptions o = FilterOptionsFromCalibration(c);
  EXPECT_EQ(o.imu.rate_hz, EskfOptions{}.imu.rate_hz);
  EXPECT_EQ(o.imu.accel_bias_random_walk_m_s3_sqrt_hz,
            EskfOptions{}.imu.accel_bias_random_walk_m_s3_sqrt_hz);
}

TEST(FilterOptionsFromCalibrationTest, WheelsOnWithTheCalibratedGeometry) {
  calib::BoardCalibration c = TestCalibration();
  calib::WheelCalibration w;
  w.wheel_radius_m = 0.1;
  w.track_m = 0.5;
  w.lever_arm_body_m = {0.0, 0.0, -0.25};
  w.nonholonomic_point_body_m = {0.01, 0.0, -0.35};
  w.yaw_scrub_factor = 1.3;
  w.slip_ratio_base = 0.02;
  w.slip_ratio_per_tilt_rad = 0.1;
  c.wheels = w;
  const EskfOptions o = FilterOptionsFromCalibration(c);
  EXPECT_TRUE(o.wheels.enabled);
  EXPECT_EQ(o.wheels.wheel_radius_m, 0.1);
  EXPECT_EQ(o.wheels.track_m, 0.5);
  EXPECT_EQ(o.wheels.yaw_scrub_factor, 1.3);
  EXPECT_EQ(o.wheels.lever_arm_body_m, Eigen::Vector3d(0.0, 0.0, -0.25));
  EXPECT_EQ(o.wheels.nonholonomic_point_body_m, Eigen::Vector3d(0.01, 0.0, -0.35));
  EXPECT_EQ(o.wheels.slip_ratio_base, 0.02);
  EXPECT_EQ(o.wheels.slip_ratio_per_tilt_rad, 0.1);

  // A file that switches the wheels off wins; one that does not keeps them.
  testing::TempDir dir;
  EXPECT_FALSE(
      FilterOptionsFromCalibration(c, WriteFile(dir, "off.yaml", "wheels:\n  enabled: false\n"))
          .wheels.enabled);
  const EskfOptions kept =
      FilterOptionsFromCalibration(c, WriteFile(dir, "track.yaml", "wheels:\n  track_m: 0.6\n"));
  EXPECT_TRUE(kept.wheels.enabled);
  EXPECT_EQ(kept.wheels.track_m, 0.6);
  EXPECT_EQ(kept.wheels.wheel_radius_m, 0.1);
}

TEST(FilterOptionsFromCalibrationTest, ShippedEurocConfigLoads) {
  const char* source = std::getenv("ROVER_SOURCE_DIR");
  ASSERT_NE(source, nullptr) << "ROVER_SOURCE_DIR is set by rover_add_test";
  const EskfOptions o = FilterOptionsFromCalibration(
      TestCalibration(), std::string(source) + "/host/eval/config/euroc_mav.yaml");
  EXPECT_EQ(o.init.window_s, 0.5);
  EXPECT_FALSE(o.zupt.enabled);
  EXPECT_FALSE(o.wheels.enabled);
  EXPECT_EQ(o.imu.accel_noise_density_m_s2_sqrt_hz, 2.0e-3);
}

TEST(FilterOptionsFromCalibrationTest, BadFileIsAnErrorNamingFileAndKey) {
  testing::TempDir dir;
  const std::string path = WriteFile(dir, "bad.yaml", "init:\n  window_sec: 0.5\n");
  try {
    FilterOptionsFromCalibration(TestCalibration(), path);
    FAIL() << "expected a ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_THAT(e.what(), HasSubstr("bad.yaml"));
    EXPECT_THAT(e.what(), HasSubstr("window_sec"));
  }
}

TEST(VoOptionsFromCalibrationTest, NominalRateFromTheCameraUnlessTheFileSetsIt) {
  EXPECT_EQ(VoOptionsFromCalibration(20.0).checks.nominal_rate_hz, 20.0);
  testing::TempDir dir;
  const std::string path = WriteFile(dir, "vo.yaml", "checks:\n  nominal_rate_hz: 10\n");
  EXPECT_EQ(VoOptionsFromCalibration(20.0, path).checks.nominal_rate_hz, 10.0);
}

}  // namespace
}  // namespace rover::estimator
