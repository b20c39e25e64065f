#include "hil/sim/dataset/euroc_writer.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <random>
#include <sstream>

#include "core/calib/euroc_sensor_yaml.h"
#include "drivers/replay/euroc_dataset.h"
#include "tests/support/temp_dir.h"

namespace rover::sim {
namespace {

namespace fs = std::filesystem;

calib::CameraModel Camera(double x) {
  calib::CameraModel c;
  c.width_px = 64;
  c.height_px = 48;
  c.rate_hz = 20;
  c.intrinsics = {40.5, 40.25, 31.75, 23.5};
  c.distortion = {-0.28, 0.07, 1.9e-4, 1.7e-5};
  c.T_body_cam.linear() =
      Eigen::AngleAxisd(0.3, Eigen::Vector3d(0.2, -1, 0.5).normalized()).toRotationMatrix();
  c.T_body_cam.translation() = Eigen::Vector3d(0.3, x, 0.5);
  return c;
}

// Writes a small dataset from seeded data; returns what was written.
struct Written {
  std::vector<drivers::ImuSample> imu;
  std::vector<cv::Mat> cam0;
  std::vector<drivers::GroundTruthState> gt;
};

Written WriteDataset(const std::string& dir) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  Written w;
  EurocWriter writer(dir);
  calib::ImuCalibration imu_cal;
  imu_cal.rate_hz = 400;
  imu_cal.gyro_noise_density_rad_s_sqrt_hz = 1.7e-4;
  imu_cal.gyro_random_walk_rad_s2_sqrt_hz = 2e-5;
  imu_cal.accel_noise_density_m_s2_sqrt_hz = 6e-4;
  imu_cal.accel_random_walk_m_s3_sqrt_hz = 1e-4;
  writer.WriteImuCalibration(imu_cal);
  writer.WriteCameraCalibration(0, Camera(0.045));
  writer.WriteCameraCalibration(1, Camera(-0.045));
  for (int i = 0; i < 40; ++i) {
    drivers::ImuSample s;
    s.stamp = Time::FromNanoseconds(1'000'000'000 + int64_t{i} * 2'500'000);
    s.angular_velocity_rad_s = {u(rng), u(rng), u(rng)};
    s.linear_acceleration_m_s2 = {u(rng), u(rng), 9.8 + u(rng)};
    writer.AddImu(s);
    w.imu.push_back(s);
  }
  cv::RNG image_rng(11);  // not cv::theRNG(): its global state would differ between calls
  for (int i = 0; i < 3; ++i) {
    const Time t = Time::FromNanoseconds(1'000'000'000 + int64_t{i} * 50'000'000);
    cv::Mat a(48, 64, CV_8UC1), b(48, 64, CV_8UC1);
    image_rng.fill(a, cv::RNG::UNIFORM, 0, 256);
    image_rng.fill(b, cv::RNG::UNIFORM, 0, 256);
    writer.AddStereo(t, a, b);
    cv::Mat depth(48, 64, CV_32F, cv::Scalar(5.0f));
    depth.at<float>(0, 0) = std::numeric_limits<float>::quiet_NaN();
    writer.AddDepth(t, depth);
    w.cam0.push_back(a);
    drivers::GroundTruthState g;
    g.stamp = t;
    g.p_world_body = {u(rng), u(rng), u(rng)};
    g.q_world_body = Eigen::Quaterniond(Eigen::AngleAxisd(u(rng), Eigen::Vector3d::UnitZ()));
    g.v_world_body_m_s = {0.3, 0, 0};
    g.gyro_bias_rad_s = {1e-3, 0, 0};
    g.accel_bias_m_s2 = {0, 0.02, 0};
    writer.AddGroundTruth(g);
    w.gt.push_back(g);
  }
  writer.AddCanFrame({Time::FromNanoseconds(5), 0x181, 8, {1, 2, 3, 4, 5, 6, 7, 8}});
  writer.Close();
  return w;
}

std::string ReadAll(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(EurocWriterTest, OurReaderReadsBackExactly) {
  const testing::TempDir dir("euroc_writer");
  const Written w = WriteDataset(dir.path().string());
  const drivers::EurocDataset d = drivers::EurocDataset::Load(dir.path().string());
  ASSERT_EQ(d.imu().size(), w.imu.size());
  for (std::size_t i = 0; i < w.imu.size(); ++i) {
    EXPECT_EQ(d.imu()[i].stamp, w.imu[i].stamp);
    EXPECT_EQ(d.imu()[i].angular_velocity_rad_s, w.imu[i].angular_velocity_rad_s);
    EXPECT_EQ(d.imu()[i].linear_acceleration_m_s2, w.imu[i].linear_acceleration_m_s2);
  }
  ASSERT_EQ(d.stereo_frames().size(), 3u);
  const cv::Mat back = cv::imread(d.stereo_frames()[1].cam0_path, cv::IMREAD_GRAYSCALE);
  EXPECT_EQ(cv::countNonZero(back != w.cam0[1]), 0);
  const calib::CameraModel expected = Camera(0.045);
  EXPECT_EQ(d.cam0().intrinsics, expected.intrinsics);
  EXPECT_EQ(d.cam0().distortion, expected.distortion);
  EXPECT_TRUE(d.cam0().T_body_cam.isApprox(expected.T_body_cam, 1e-12));
  EXPECT_DOUBLE_EQ(d.imu_calibration().gyro_noise_density_rad_s_sqrt_hz, 1.7e-4);
  ASSERT_EQ(d.ground_truth().size(), 3u);
  EXPECT_EQ(d.ground_truth()[2].p_world_body, w.gt[2].p_world_body);
  EXPECT_NEAR(d.ground_truth()[2].q_world_body.angularDistance(w.gt[2].q_world_body), 0, 1e-12);
  EXPECT_EQ(d.ground_truth()[2].accel_bias_m_s2, w.gt[2].accel_bias_m_s2);
  EXPECT_TRUE(d.issues().empty()) << d.issues().front();

  const cv::Mat depth =
      cv::imread((dir.path() / "mav0/depth0/data/1000000000.png").string(), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(depth.type(), CV_16UC1);
  EXPECT_EQ(depth.at<uint16_t>(0, 0), 0);  // no surface
  EXPECT_EQ(depth.at<uint16_t>(10, 10), 5000);
  EXPECT_EQ(ReadAll(dir.path() / "mav0/can0/data.csv"),
            "#timestamp [ns],id,dlc,data_hex\n5,0x181,8,0102030405060708\n");
}

TEST(EurocWriterTest, WritesTheCameraDistortionModel) {
  const testing::TempDir dir("euroc_writer");
  calib::CameraModel fisheye = Camera(0.045);
  fisheye.distortion_model = calib::DistortionModel::kEquidistant;
  fisheye.distortion = {0.0034, 0.0007, -0.0021, 0.0002};
  {
    EurocWriter writer(dir.path().string());
    writer.WriteCameraCalibration(0, fisheye);
    writer.WriteCameraCalibration(1, Camera(-0.045));
  }
  const calib::CameraModel cam0 =
      calib::LoadEurocCamera(dir.File("mav0/cam0/sensor.yaml").string());
  EXPECT_EQ(cam0.distortion_model, calib::DistortionModel::kEquidistant);
  EXPECT_EQ(cam0.distortion, fisheye.distortion);
  EXPECT_EQ(calib::LoadEurocCamera(dir.File("mav0/cam1/sensor.yaml").string()).distortion_model,
            calib::DistortionModel::kRadialTangential);
}

TEST(EurocWriterTest, SameInputGivesByteIdenticalFiles) {
  const testing::TempDir a("euroc_a"), b("euroc_b");
  WriteDataset(a.path().string());
  WriteDataset(b.path().string());
  std::size_t files = 0;
  for (const auto& entry : fs::recursive_directory_iterator(a.path())) {
    if (!entry.is_regular_file()) continue;
    const fs::path relative = fs::relative(entry.path(), a.path());
    ASSERT_TRUE(ReadAll(entry.path()) == ReadAll(b.path() / relative)) << relative << " differs";
    ++files;
  }
  EXPECT_GT(files, 15u);
}

TEST(EurocWriterTest, RefusesToMixWithAnExistingDataset) {
  const testing::TempDir dir("euroc_writer");
  fs::create_directories(dir.path() / "mav0");
  EXPECT_THROW(EurocWriter(dir.path().string()), drivers::DatasetError);
}

}  // namespace
}  // namespace rover::sim
