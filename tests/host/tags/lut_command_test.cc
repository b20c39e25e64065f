#include "host/tags/lut_command.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <sstream>

#include "core/calib/board_calibration.h"
#include "core/calib/stereo_rectifier.h"
#include "tests/support/temp_dir.h"

namespace rover::host {
namespace {

namespace fs = std::filesystem;

// A board with a 752x480 stereo head, 12 cm baseline, no distortion.
calib::BoardCalibration Board(bool with_cameras) {
  calib::BoardCalibration board;
  board.imu.rate_hz = 200;
  board.imu.gyro_noise_density_rad_s_sqrt_hz = 1.7e-4;
  board.imu.gyro_random_walk_rad_s2_sqrt_hz = 1.9e-5;
  board.imu.accel_noise_density_m_s2_sqrt_hz = 2e-3;
  board.imu.accel_random_walk_m_s3_sqrt_hz = 3e-3;
  if (with_cameras) {
    calib::CameraModel cam;
    cam.width_px = 752;
    cam.height_px = 480;
    cam.rate_hz = 10;
    cam.intrinsics = {450.0, 450.0, 375.5, 239.5};
    calib::StereoCalibration stereo{cam, cam};
    stereo.cam1.T_body_cam.translation() = Eigen::Vector3d(0.12, 0.0, 0.0);
    board.stereo = stereo;
  }
  return board;
}

LutCommandOptions SmallGrid(const std::string& calibration) {
  LutCommandOptions o;
  o.calibration = calibration;
  o.spec.tag_size_m = 0.16;
  o.spec.min_distance_m = 0.5;
  o.spec.max_distance_m = 3.0;
  o.spec.distance_steps = 4;
  o.spec.tilt_steps = 5;
  return o;
}

TEST(LutCommandTest, WritesTheTableBesideTheCalibrationForItsRectifiedCamera) {
  const testing::TempDir dir;
  const std::string calibration = (dir.path() / "board.yaml").string();
  Board(true).SaveFile(calibration);
  std::ostringstream out, err;
  ASSERT_EQ(RunLut(SmallGrid(calibration), out, err), 0) << err.str();
  const std::string path = (dir.path() / "tag_errors_tag36h11_160mm.yaml").string();
  EXPECT_EQ(TagErrorTablePath(calibration, "tag36h11", 0.16), path);
  ASSERT_TRUE(fs::exists(path)) << out.str();
  EXPECT_NE(out.str().find("RESULT cells=20 detected_cells="), std::string::npos) << out.str();
  EXPECT_NE(err.str().find("100.0 % (20 of 20 cells)"), std::string::npos) << err.str();
  const mapping::TagErrorTable table = mapping::TagErrorTable::Load(path);
  const calib::BoardCalibration board = Board(true);
  const auto rectifier = calib::StereoRectifier::Create(board.stereo->cam0, board.stereo->cam1);
  ASSERT_TRUE(rectifier.has_value());
  EXPECT_NO_THROW(
      table.CheckMatches(rectifier->intrinsics(), rectifier->image_size(), "tag36h11", 0.16));
  // 0.5-3 m: all but the +-89 degree tilts are seen.
  EXPECT_EQ(table.detected_cells(), 12u);
}

TEST(LutCommandTest, SaysWhatIsWrongWithTheInput) {
  const testing::TempDir dir;
  const std::string calibration = (dir.path() / "imu_only.yaml").string();
  Board(false).SaveFile(calibration);
  std::ostringstream out, err;
  EXPECT_EQ(RunLut(SmallGrid(calibration), out, err), 1);
  EXPECT_NE(err.str().find("imu_only.yaml: expected a `cameras` section"), std::string::npos)
      << err.str();

  const std::string good = (dir.path() / "board.yaml").string();
  Board(true).SaveFile(good);
  LutCommandOptions bad_family = SmallGrid(good);
  bad_family.spec.family = "tag99h1";
  err.str("");
  EXPECT_EQ(RunLut(bad_family, out, err), 1);
  EXPECT_NE(err.str().find("'tag99h1'"), std::string::npos) << err.str();

  LutCommandOptions unwritable = SmallGrid(good);
  unwritable.output = (dir.path() / "no_such_dir" / "t.yaml").string();
  err.str("");
  EXPECT_EQ(RunLut(unwritable, out, err), 2);
  EXPECT_NE(err.str().find("no_such_dir"), std::string::npos) << err.str();
}

}  // namespace
}  // namespace rover::host
