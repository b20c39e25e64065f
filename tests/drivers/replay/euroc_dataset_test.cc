#include "drivers/replay/euroc_dataset.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "core/calib/euroc_sensor_yaml.h"
#include "drivers/replay/euroc_replay.h"
#include "tests/support/temp_dir.h"

namespace rover::drivers {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

std::string MicroEuroc() {
  const char* shared = std::getenv("ROVER_SHARED_DIR");
  return std::string(shared != nullptr ? shared : "../shared") + "/data/euroc_v1_01_micro";
}

// The real EuRoC V1_01 excerpt: 95 stereo pairs (cam1 lists 4 extra rows
// without images), the whole 200 Hz IMU record, no GT CSV in mav0.
TEST(EurocDatasetTest, LoadsTheRealMicroExcerpt) {
  const EurocDataset d = EurocDataset::Load(MicroEuroc());
  EXPECT_EQ(d.imu().size(), 29120u);
  EXPECT_EQ(d.stereo_frames().size(), 95u);
  EXPECT_EQ(d.stereo_frames().front().stamp.nanoseconds(), 1403715273262142976);
  EXPECT_NEAR(d.imu().front().linear_acceleration_m_s2.x(), 9.0874956666666655, 1e-12);
  EXPECT_EQ(d.cam0().width_px, 752);
  EXPECT_DOUBLE_EQ(d.cam0().intrinsics[0], 458.654);
  EXPECT_DOUBLE_EQ(d.cam0().distortion[0], -0.28340811);
  EXPECT_NEAR(d.cam0().T_body_cam.translation().x(), -0.0216401454975, 1e-12);
  // The stereo baseline of the VI-Sensor is about 11 cm.
  const double baseline =
      (d.cam0().T_body_cam.translation() - d.cam1().T_body_cam.translation()).norm();
  EXPECT_NEAR(baseline, 0.110, 0.002);
  EXPECT_DOUBLE_EQ(d.imu_calibration().gyro_noise_density_rad_s_sqrt_hz, 1.6968e-04);
  // One calibration, as core/calib reads the sensor.yaml files.
  EXPECT_EQ(d.calibration(), calib::LoadEurocCalibration(MicroEuroc() + "/mav0"));
  EXPECT_FALSE(d.calibration().wheels.has_value());
  EXPECT_TRUE(d.ground_truth().empty());
  // The 4 cam1 rows without images are reported, not silently lost.
  bool reported_missing = false;
  for (const std::string& issue : d.issues()) {
    reported_missing |= issue.find("missing") != std::string::npos;
  }
  EXPECT_TRUE(reported_missing);
}

TEST(EurocDatasetTest, ExternalOpenVinsGroundTruthAndInterpolation) {
  const EurocDataset d =
      EurocDataset::Load(MicroEuroc(), MicroEuroc() + "/groundtruth/V1_01_easy_openvins.csv");
  ASSERT_GT(d.ground_truth().size(), 1000u);
  const GroundTruthState& first = d.ground_truth().front();
  EXPECT_NEAR(first.p_world_body.x(), 0.878895, 1e-9);
  const auto mid = d.GroundTruthAt(first.stamp + Duration::Milliseconds(25));
  ASSERT_TRUE(mid.has_value());
  EXPECT_NEAR(mid->p_world_body.x(), 0.5 * (0.878895 + 0.878973), 1e-9);
  EXPECT_FALSE(d.GroundTruthAt(first.stamp - Duration::Seconds(1)).has_value());
}

TEST(EurocReplayTest, LockstepDeliversEverythingInOrderThroughDriverInterfaces) {
  const EurocDataset d = EurocDataset::Load(MicroEuroc());
  const ReplayClock clock(false, d.imu().front().stamp);
  EurocImuReplay imu(d, clock);
  EurocStereoReplay stereo(d, clock);
  ImuSample sample;
  std::size_t imu_count = 0;
  Time last;
  while (imu.Read(&sample, Duration::Milliseconds(10)) == ReadStatus::kOk) {
    if (imu_count > 0) {
      ASSERT_GT(sample.stamp, last);
    }
    last = sample.stamp;
    ++imu_count;
  }
  EXPECT_EQ(imu_count, d.imu().size());
  StereoFrame frame;
  std::size_t frames = 0;
  while (stereo.Next(&frame, Duration::Milliseconds(10)) == ReadStatus::kOk) {
    EXPECT_EQ(frame.cam0.width_px, 752);
    EXPECT_EQ(frame.cam1.height_px, 480);
    ASSERT_NE(frame.cam0.data, nullptr);
    stereo.Release(frame);
    ++frames;
  }
  EXPECT_EQ(frames, 95u);
  EXPECT_EQ(stereo.Next(&frame, Duration::Zero()), ReadStatus::kEndOfStream);
}

// A copy of the dataset's metadata with one damaged IMU line.
class DamagedDatasetTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const fs::path src = fs::path(MicroEuroc()) / "mav0";
    for (const char* sub : {"imu0", "cam0", "cam1"}) {
      fs::create_directories(dir_.path() / "mav0" / sub / "data");
      fs::copy_file(src / sub / "sensor.yaml", dir_.path() / "mav0" / sub / "sensor.yaml");
      std::ofstream(dir_.path() / "mav0" / sub / "data.csv") << "#timestamp [ns],filename\n";
    }
  }
  void WriteImu(const std::string& body) {
    std::ofstream(dir_.path() / "mav0/imu0/data.csv")
        << "#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y,w_RS_S_z,a_x,a_y,a_z\n"
        << body;
  }
  testing::TempDir dir_{"euroc"};
};

TEST_F(DamagedDatasetTest, NonNumericValueNamesFileAndLine) {
  WriteImu("100,0,0,0,0,0,9.8\n200,0,0,abc,0,0,9.8\n");
  try {
    EurocDataset::Load(dir_.path().string());
    FAIL() << "expected DatasetError";
  } catch (const DatasetError& e) {
    EXPECT_THAT(e.what(), HasSubstr("imu0/data.csv:3"));
    EXPECT_THAT(e.what(), HasSubstr("'abc'"));
  }
}

TEST_F(DamagedDatasetTest, OutOfOrderTimestampIsAnError) {
  WriteImu("100,0,0,0,0,0,9.8\n300,0,0,0,0,0,9.8\n200,0,0,0,0,0,9.8\n");
  try {
    EurocDataset::Load(dir_.path().string());
    FAIL() << "expected DatasetError";
  } catch (const DatasetError& e) {
    EXPECT_THAT(e.what(), HasSubstr("imu0/data.csv:4"));
    EXPECT_THAT(e.what(), HasSubstr("does not increase"));
  }
}

TEST_F(DamagedDatasetTest, NanAndShortRowsAreErrors) {
  WriteImu("100,0,0,nan,0,0,9.8\n");
  EXPECT_THROW(EurocDataset::Load(dir_.path().string()), DatasetError);
  WriteImu("100,0,0\n");
  EXPECT_THROW(EurocDataset::Load(dir_.path().string()), DatasetError);
}

TEST_F(DamagedDatasetTest, BadCalibrationIsADatasetErrorNamingTheFile) {
  WriteImu("100,0,0,0,0,0,9.8\n");
  std::ofstream(dir_.path() / "mav0/cam1/sensor.yaml")
      << "%YAML:1.0\nresolution: [752, 480]\nrate_hz: 20\ncamera_model: pinhole\n"
         "distortion_model: fov\n";
  try {
    EurocDataset::Load(dir_.path().string());
    FAIL() << "expected DatasetError";
  } catch (const DatasetError& e) {
    EXPECT_THAT(e.what(), HasSubstr("cam1/sensor.yaml: expected camera_model pinhole"));
    EXPECT_THAT(e.what(), HasSubstr("'fov'"));
  }
}

TEST(EurocDatasetErrorTest, NotADataset) {
  EXPECT_THROW(EurocDataset::Load("/nonexistent"), DatasetError);
}

}  // namespace
}  // namespace rover::drivers
