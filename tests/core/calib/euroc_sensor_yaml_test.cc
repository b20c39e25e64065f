#include "core/calib/euroc_sensor_yaml.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <string>

#include "tests/support/temp_dir.h"

namespace rover::calib {
namespace {

using ::testing::HasSubstr;

std::string MicroEurocMav0() {
  const char* shared = std::getenv("ROVER_SHARED_DIR");
  return std::string(shared != nullptr ? shared : "../shared") + "/data/euroc_v1_01_micro/mav0";
}

constexpr std::string_view kCamera = R"(%YAML:1.0
sensor_type: camera
T_BS:
  cols: 4
  rows: 4
  data: [1.0, 0.0, 0.0, 0.05,
         0.0, 1.0, 0.0, 0.0,
         0.0, 0.0, 1.0, 0.0,
         0.0, 0.0, 0.0, 1.0]
rate_hz: 20
resolution: [512, 512]
camera_model: pinhole
intrinsics: [190.978, 190.973, 254.932, 256.897] #fu, fv, cu, cv
distortion_model: equidistant
distortion_coefficients: [0.0034823894, 0.0007150348, -0.0020532361, 0.0002029367]
)";

// Writes `text` with the first `from` replaced by `to` and returns the path.
std::string Write(const testing::TempDir& dir, std::string_view text, std::string_view from = "",
                  std::string_view to = "") {
  std::string yaml(text);
  if (!from.empty()) yaml.replace(yaml.find(from), from.size(), to);
  const std::string path = dir.File("sensor.yaml").string();
  std::ofstream(path) << yaml;
  return path;
}

std::string CameraError(const std::string& path) {
  try {
    LoadEurocCamera(path);
  } catch (const CalibrationError& e) {
    return e.what();
  }
  return "<no error>";
}

TEST(EurocSensorYamlTest, ReadsTheRealEurocFiles) {
  const CameraModel cam0 = LoadEurocCamera(MicroEurocMav0() + "/cam0/sensor.yaml");
  EXPECT_EQ(cam0.width_px, 752);
  EXPECT_EQ(cam0.height_px, 480);
  EXPECT_EQ(cam0.rate_hz, 20.0);
  EXPECT_EQ(cam0.distortion_model, DistortionModel::kRadialTangential);
  EXPECT_EQ(cam0.intrinsics[0], 458.654);
  EXPECT_EQ(cam0.distortion[0], -0.28340811);
  EXPECT_NEAR(cam0.T_body_cam.translation().x(), -0.0216401454975, 1e-12);
  EXPECT_NO_THROW(cam0.Validate());

  const ImuCalibration imu = LoadEurocImu(MicroEurocMav0() + "/imu0/sensor.yaml");
  EXPECT_EQ(imu.rate_hz, 200.0);
  EXPECT_EQ(imu.gyro_noise_density_rad_s_sqrt_hz, 1.6968e-04);
  EXPECT_EQ(imu.gyro_random_walk_rad_s2_sqrt_hz, 1.9393e-05);
  EXPECT_EQ(imu.accel_noise_density_m_s2_sqrt_hz, 2.0e-3);
  EXPECT_EQ(imu.accel_random_walk_m_s3_sqrt_hz, 3.0e-3);
  EXPECT_TRUE(imu.T_body_imu.matrix().isIdentity(0.0));
}

TEST(EurocSensorYamlTest, WholeDatasetCalibration) {
  const BoardCalibration c = LoadEurocCalibration(MicroEurocMav0());
  EXPECT_EQ(c.imu, LoadEurocImu(MicroEurocMav0() + "/imu0/sensor.yaml"));
  ASSERT_TRUE(c.stereo.has_value());
  EXPECT_EQ(c.stereo->cam0, LoadEurocCamera(MicroEurocMav0() + "/cam0/sensor.yaml"));
  EXPECT_EQ(c.stereo->cam1, LoadEurocCamera(MicroEurocMav0() + "/cam1/sensor.yaml"));
  EXPECT_FALSE(c.wheels.has_value());
  EXPECT_NO_THROW(c.Validate());
  // The EuRoC calibration survives the board format exactly.
  EXPECT_EQ(BoardCalibration::LoadString(c.ToYaml(), "euroc.yaml"), c);
}

TEST(EurocSensorYamlTest, ReadsEquidistantCameras) {
  const testing::TempDir dir("euroc_yaml");
  const CameraModel c = LoadEurocCamera(Write(dir, kCamera));
  EXPECT_EQ(c.distortion_model, DistortionModel::kEquidistant);
  EXPECT_EQ(c.distortion[3], 0.0002029367);
  EXPECT_EQ(c.T_body_cam.translation().x(), 0.05);
}

TEST(EurocSensorYamlTest, ReadsThisProjectsVignettingExtension) {
  const testing::TempDir dir("euroc_yaml");
  EXPECT_EQ(LoadEurocCamera(Write(dir, kCamera)).vignetting_cos4_strength, 0.0);
  const std::string path =
      Write(dir, kCamera, "rate_hz: 20", "rate_hz: 20\nvignetting_cos4_strength: 0.5");
  EXPECT_EQ(LoadEurocCamera(path).vignetting_cos4_strength, 0.5);
}

TEST(EurocSensorYamlTest, ErrorsNameTheFileAndKey) {
  const testing::TempDir dir("euroc_yaml");
  std::string path = Write(dir, kCamera, "distortion_model: equidistant", "distortion_model: fov");
  EXPECT_EQ(CameraError(path),
            path +
                ": expected camera_model pinhole with distortion_model radial-tangential or "
                "equidistant, found 'pinhole' / 'fov'");
  path = Write(dir, kCamera, "camera_model: pinhole", "camera_model: omni");
  EXPECT_THAT(CameraError(path), HasSubstr("found 'omni' / 'equidistant'"));
  path = Write(dir, kCamera, "[190.978, 190.973, 254.932, 256.897]", "[190.978, 190.973]");
  EXPECT_EQ(CameraError(path), path + ": intrinsics: expected 4 numbers, found 2");
  path = Write(dir, kCamera, "resolution: [512, 512]", "resolution: 512");
  EXPECT_EQ(CameraError(path), path + ": resolution: expected 2 numbers, found 0");
  path = Write(dir, kCamera, "rate_hz: 20", "rate_hz: fast");
  EXPECT_EQ(CameraError(path), path + ": rate_hz: expected a number");
  path = Write(dir, kCamera, "data: [1.0, 0.0, 0.0, 0.05,", "data: [2.0, 0.0, 0.0, 0.05,");
  EXPECT_EQ(CameraError(path), path + ": T_BS: rotation part is not orthonormal");
  path = Write(dir, kCamera, "         0.0, 0.0, 0.0, 1.0]", "         0.0, 0.0, 0.0]");
  EXPECT_EQ(CameraError(path), path + ": T_BS.data: expected 16 numbers (4x4 row-major), found 15");
  EXPECT_EQ(CameraError(dir.File("none.yaml").string()),
            dir.File("none.yaml").string() + ": missing");
  EXPECT_THROW(LoadEurocImu(path), CalibrationError);
  EXPECT_THROW(LoadEurocCalibration(dir.path().string()), CalibrationError);
}

}  // namespace
}  // namespace rover::calib
