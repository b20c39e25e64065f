#include "core/calib/board_calibration.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "tests/support/temp_dir.h"

namespace rover::calib {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

// The format's example (EuRoC V1 calibration, with wheels), line numbers as
// the error tests expect them.
constexpr std::string_view kExample = R"(format: rover-calibration-1
imu:
  rate_hz: 200
  gyro_noise_density_rad_s_sqrt_hz: 1.6968e-04
  gyro_random_walk_rad_s2_sqrt_hz: 1.9393e-05
  accel_noise_density_m_s2_sqrt_hz: 2.0e-3
  accel_random_walk_m_s3_sqrt_hz: 3.0e-3
  T_body_imu: [1, 0, 0, 0,  0, 1, 0, 0,  0, 0, 1, 0,  0, 0, 0, 1]
cameras:
  cam0:
    width_px: 752
    height_px: 480
    rate_hz: 20
    model: pinhole-radtan
    intrinsics: [458.654, 457.296, 367.215, 248.375]
    distortion: [-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05]
    T_body_cam: [0.0148655429818, -0.999880929698, 0.00414029679422, -0.0216401454975,
                 0.999557249008, 0.0149672133247, 0.025715529948, -0.064676986768,
                 -0.0257744366974, 0.00375618835797, 0.999660727178, 0.00981073058949,
                 0, 0, 0, 1]
  cam1:
    width_px: 752
    height_px: 480
    rate_hz: 20
    model: pinhole-radtan
    intrinsics: [457.587, 456.134, 379.999, 255.238]
    distortion: [-0.28368365, 0.07451284, -0.00010473, -3.55590700e-05]
    T_body_cam: [0.0125552670891, -0.999755099723, 0.0182237714554, -0.0198435579556,
                 0.999598781151, 0.0130119051815, 0.0251588363115, 0.0453689425024,
                 -0.0253898008918, 0.0179005838253, 0.999517347078, 0.00786212447038,
                 0, 0, 0, 1]
wheels:
  wheel_radius_m: 0.1
  track_m: 0.5
  lever_arm_body_m: [0, 0, -0.25]
)";

// kExample with the first occurrence of `from` replaced by `to`.
std::string Edited(std::string_view from, std::string_view to) {
  std::string yaml(kExample);
  const std::size_t at = yaml.find(from);
  if (at == std::string::npos) throw std::logic_error("not in the example: " + std::string(from));
  return yaml.replace(at, from.size(), to);
}

std::string LoadError(const std::string& yaml) {
  try {
    BoardCalibration::LoadString(yaml, "cal.yaml");
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "<no error>";
}

// Every double of `c`, in a fixed order, for bit-for-bit comparison.
std::vector<double> Doubles(const BoardCalibration& c) {
  std::vector<double> out = {
      c.imu.rate_hz, c.imu.gyro_noise_density_rad_s_sqrt_hz, c.imu.gyro_random_walk_rad_s2_sqrt_hz,
      c.imu.accel_noise_density_m_s2_sqrt_hz, c.imu.accel_random_walk_m_s3_sqrt_hz};
  const auto matrix = [&](const Eigen::Isometry3d& T) {
    for (int i = 0; i < 16; ++i) out.push_back(T.matrix()(i / 4, i % 4));
  };
  matrix(c.imu.T_body_imu);
  if (c.stereo) {
    for (const CameraModel* cam : {&c.stereo->cam0, &c.stereo->cam1}) {
      out.push_back(cam->rate_hz);
      out.insert(out.end(), cam->intrinsics.begin(), cam->intrinsics.end());
      out.insert(out.end(), cam->distortion.begin(), cam->distortion.end());
      matrix(cam->T_body_cam);
    }
  }
  if (c.wheels) {
    out.push_back(c.wheels->wheel_radius_m);
    out.push_back(c.wheels->track_m);
    out.insert(out.end(), c.wheels->lever_arm_body_m.data(), c.wheels->lever_arm_body_m.data() + 3);
  }
  return out;
}

void ExpectBitIdentical(const BoardCalibration& a, const BoardCalibration& b) {
  EXPECT_EQ(a, b);
  const std::vector<double> da = Doubles(a), db = Doubles(b);
  ASSERT_EQ(da.size(), db.size());
  for (std::size_t i = 0; i < da.size(); ++i) {
    EXPECT_EQ(std::bit_cast<uint64_t>(da[i]), std::bit_cast<uint64_t>(db[i]))
        << "value " << i << ": " << da[i] << " vs " << db[i];
  }
}

// Random values, with the awkward ones (negative zero, subnormals, the
// smallest normal, huge magnitudes) mixed in often.
class RandomCalibration {
 public:
  explicit RandomCalibration(uint64_t seed) : rng_(seed) {}

  double Any() {
    static constexpr double kEdge[] = {0.0,
                                       -0.0,
                                       std::numeric_limits<double>::denorm_min(),
                                       -std::numeric_limits<double>::denorm_min(),
                                       4.9406564584124654e-320,
                                       std::numeric_limits<double>::min(),
                                       -std::numeric_limits<double>::min(),
                                       2.2250738585072009e-308,  // the largest subnormal
                                       1e300,
                                       -1.7976931348623157e308,
                                       0.1,
                                       1.0 / 3.0};
    if (Uniform(0, 1) < 0.3) return kEdge[Index(std::size(kEdge))];
    return std::ldexp(Uniform(-1, 1), static_cast<int>(Index(80)) - 40);
  }
  double Positive() {
    const double v = std::abs(Any());
    return v > 0.0 ? v : std::numeric_limits<double>::denorm_min();
  }
  Eigen::Isometry3d Transform() {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    if (Uniform(0, 1) < 0.2) {
      // Axis permutations hold exact zeros, some of them negative.
      T.linear() << 0.0, -1.0, -0.0, 1.0, 0.0, 0.0, -0.0, 0.0, 1.0;
    } else {
      T.linear() =
          Eigen::Quaterniond(Uniform(-1, 1), Uniform(-1, 1), Uniform(-1, 1), Uniform(-1, 1))
              .normalized()
              .toRotationMatrix();
    }
    T.translation() = Eigen::Vector3d(Any(), Any(), Any());
    return T;
  }
  CameraModel Camera() {
    CameraModel c;
    c.width_px = 1 + static_cast<int>(Index(4096));
    c.height_px = 1 + static_cast<int>(Index(4096));
    c.rate_hz = Positive();
    c.distortion_model =
        Index(2) == 0 ? DistortionModel::kRadialTangential : DistortionModel::kEquidistant;
    c.intrinsics = {Positive(), Positive(), Any(), Any()};
    c.distortion = {Any(), Any(), Any(), Any()};
    c.T_body_cam = Transform();
    c.vignetting_cos4_strength =
        Index(2) == 0 ? 0.0 : static_cast<double>(Index(999983)) / 1000003.0;
    return c;
  }
  BoardCalibration Board() {
    BoardCalibration c;
    c.imu.rate_hz = Positive();
    c.imu.gyro_noise_density_rad_s_sqrt_hz = Positive();
    c.imu.gyro_random_walk_rad_s2_sqrt_hz = Positive();
    c.imu.accel_noise_density_m_s2_sqrt_hz = Positive();
    c.imu.accel_random_walk_m_s3_sqrt_hz = Positive();
    c.imu.T_body_imu = Transform();
    if (Index(3) != 0) c.stereo = StereoCalibration{Camera(), Camera()};
    if (Index(3) != 0) {
      c.wheels = WheelCalibration{Positive(), Positive(), Eigen::Vector3d(Any(), Any(), Any())};
    }
    return c;
  }

 private:
  double Uniform(double lo, double hi) {
    return std::uniform_real_distribution<double>(lo, hi)(rng_);
  }
  std::size_t Index(std::size_t n) {
    return std::uniform_int_distribution<std::size_t>(0, n - 1)(rng_);
  }
  std::mt19937_64 rng_;
};

TEST(BoardCalibrationTest, LoadsTheExample) {
  const BoardCalibration c = BoardCalibration::LoadString(kExample, "cal.yaml");
  EXPECT_EQ(c.imu.rate_hz, 200.0);
  EXPECT_EQ(c.imu.gyro_noise_density_rad_s_sqrt_hz, 1.6968e-04);
  EXPECT_EQ(c.imu.accel_random_walk_m_s3_sqrt_hz, 3.0e-3);
  EXPECT_TRUE(c.imu.T_body_imu.matrix().isIdentity(0.0));
  ASSERT_TRUE(c.stereo.has_value());
  EXPECT_EQ(c.stereo->cam0.width_px, 752);
  EXPECT_EQ(c.stereo->cam0.height_px, 480);
  EXPECT_EQ(c.stereo->cam0.rate_hz, 20.0);
  EXPECT_EQ(c.stereo->cam0.distortion_model, DistortionModel::kRadialTangential);
  EXPECT_EQ(c.stereo->cam0.intrinsics[0], 458.654);
  EXPECT_EQ(c.stereo->cam1.distortion[3], -3.55590700e-05);
  // Used as written, not re-orthonormalised.
  EXPECT_EQ(c.stereo->cam0.T_body_cam.matrix()(0, 0), 0.0148655429818);
  EXPECT_EQ(c.stereo->cam1.T_body_cam.translation().z(), 0.00786212447038);
  ASSERT_TRUE(c.wheels.has_value());
  EXPECT_EQ(c.wheels->wheel_radius_m, 0.1);
  EXPECT_EQ(c.wheels->track_m, 0.5);
  EXPECT_EQ(c.wheels->lever_arm_body_m, Eigen::Vector3d(0, 0, -0.25));
  EXPECT_NO_THROW(c.Validate());
}

TEST(BoardCalibrationTest, CamerasAndWheelsAreOptional) {
  const std::string imu_only(kExample.substr(0, kExample.find("cameras:")));
  const BoardCalibration c = BoardCalibration::LoadString(imu_only, "cal.yaml");
  EXPECT_FALSE(c.stereo.has_value());
  EXPECT_FALSE(c.wheels.has_value());
  EXPECT_EQ(BoardCalibration::LoadString(c.ToYaml(), "again.yaml"), c);
}

TEST(BoardCalibrationTest, ExampleRoundTripsBitForBit) {
  const BoardCalibration c = BoardCalibration::LoadString(kExample, "cal.yaml");
  const std::string yaml = c.ToYaml();
  EXPECT_THAT(yaml, HasSubstr("format: rover-calibration-1\n"));
  EXPECT_THAT(yaml, HasSubstr("    intrinsics: [458.654, 457.296, 367.215, 248.375]"));
  EXPECT_THAT(yaml, HasSubstr("    model: pinhole-radtan\n"));
  ExpectBitIdentical(BoardCalibration::LoadString(yaml, "written.yaml"), c);
}

TEST(BoardCalibrationTest, RandomCalibrationsRoundTripBitForBit) {
  RandomCalibration random(20240611);
  for (int i = 0; i < 300; ++i) {
    const BoardCalibration c = random.Board();
    ASSERT_NO_THROW(c.Validate()) << "case " << i;
    const std::string yaml = c.ToYaml();
    BoardCalibration back;
    ASSERT_NO_THROW(back = BoardCalibration::LoadString(yaml, "random.yaml")) << yaml;
    ExpectBitIdentical(back, c);
    if (::testing::Test::HasFailure()) {
      ADD_FAILURE() << "case " << i << ":\n" << yaml;
      break;
    }
  }
}

TEST(BoardCalibrationTest, SaveFileAndLoadFile) {
  const testing::TempDir dir("calib");
  const std::string path = dir.File("board.yaml").string();
  RandomCalibration random(7);
  const BoardCalibration c = random.Board();
  c.SaveFile(path);
  EXPECT_FALSE(std::filesystem::exists(path + ".tmp"));
  ExpectBitIdentical(BoardCalibration::LoadFile(path), c);
  // Saving again replaces the file.
  BoardCalibration other = c;
  other.imu.rate_hz = 400.0;
  other.SaveFile(path);
  EXPECT_EQ(BoardCalibration::LoadFile(path).imu.rate_hz, 400.0);
}

TEST(BoardCalibrationTest, SaveFileRefusesInvalidCalibrationsAndUnwritablePaths) {
  const testing::TempDir dir("calib");
  BoardCalibration c = BoardCalibration::LoadString(kExample, "cal.yaml");
  c.stereo->cam1.intrinsics[1] = 0.0;
  try {
    c.SaveFile(dir.File("bad.yaml").string());
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()),
              "cameras.cam1.intrinsics: expected focal lengths fu, fv > 0 px, found fu = "
              "457.587, fv = 0");
  }
  EXPECT_FALSE(std::filesystem::exists(dir.File("bad.yaml")));
  const BoardCalibration good = BoardCalibration::LoadString(kExample, "cal.yaml");
  try {
    good.SaveFile(dir.File("no/such/folder/board.yaml").string());
    FAIL() << "expected std::runtime_error";
  } catch (const std::runtime_error& e) {
    EXPECT_THAT(e.what(), HasSubstr("no/such/folder/board.yaml.tmp: cannot create"));
  }
}

TEST(BoardCalibrationTest, LoadFileNamesTheFile) {
  const testing::TempDir dir("calib");
  const std::string path = dir.File("board.yaml").string();
  std::ofstream(path) << Edited("  track_m: 0.5", "  track_m: -0.5");
  try {
    BoardCalibration::LoadFile(path);
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()),
              path + ":34: wheels.track_m: expected a finite track > 0 m, found -0.5");
  }
  EXPECT_THROW(BoardCalibration::LoadFile(dir.File("missing.yaml").string()), ConfigError);
}

TEST(BoardCalibrationTest, FormatMustBeNamed) {
  EXPECT_EQ(LoadError(Edited("format: rover-calibration-1", "format: rover-calibration-2")),
            "cal.yaml:1: format: expected rover-calibration-1, found 'rover-calibration-2'");
  EXPECT_EQ(LoadError(Edited("format: rover-calibration-1\n", "")),
            "cal.yaml:1: format: missing required key");
}

TEST(BoardCalibrationTest, UnknownKeysAreErrors) {
  EXPECT_THAT(LoadError(Edited("wheels:", "gps: {}\nwheels:")),
              HasSubstr("cal.yaml:32: gps: unknown key"));
  EXPECT_THAT(LoadError(Edited("    width_px: 752", "    widht_px: 752\n    width_px: 752")),
              HasSubstr("cal.yaml:11: cameras.cam0.widht_px: unknown key"));
  EXPECT_THAT(LoadError(Edited("  cam1:", "  cam2: {}\n  cam1:")),
              HasSubstr("cal.yaml:21: cameras.cam2: unknown key"));
}

TEST(BoardCalibrationTest, MissingSectionsAndCameras) {
  EXPECT_EQ(LoadError(Edited("  cam1:", "  camera1:")),
            "cal.yaml:9: cameras.cam1: missing required key");
  EXPECT_EQ(LoadError(Edited("    rate_hz: 20\n", "")),
            "cal.yaml:10: cameras.cam0.rate_hz: missing required key");
}

TEST(BoardCalibrationTest, WrongVectorLengths) {
  EXPECT_EQ(
      LoadError(Edited("[458.654, 457.296, 367.215, 248.375]", "[458.654, 457.296, 367.215]")),
      "cal.yaml:15: cameras.cam0.intrinsics: expected a list of 4 numbers, found a list of 3 "
      "elements");
  EXPECT_EQ(LoadError(Edited("[0, 0, -0.25]", "[0, -0.25]")),
            "cal.yaml:35: wheels.lever_arm_body_m: expected a list of 3 numbers, found a list of 2 "
            "elements");
  EXPECT_THAT(LoadError(Edited("0, 0, 1, 0,  0, 0, 0, 1]", "0, 0, 1, 0,  0, 0, 0]")),
              HasSubstr("cal.yaml:8: imu.T_body_imu: expected a 4x4 matrix"));
}

TEST(BoardCalibrationTest, TransformsMustBeRigid) {
  // Scaled: not orthonormal.
  EXPECT_THAT(LoadError(Edited("[1, 0, 0, 0,  0, 1, 0, 0,", "[1.001, 0, 0, 0,  0, 1, 0, 0,")),
              HasSubstr("cal.yaml:8: imu.T_body_imu: expected an orthonormal rotation part "
                        "(|R^T R - I| <= 1e-06), found |R^T R - I| = 0.002"));
  // Within the tolerance is accepted as written.
  EXPECT_EQ(LoadError(Edited("[1, 0, 0, 0,  0, 1, 0, 0,", "[1.0000001, 0, 0, 0,  0, 1, 0, 0,")),
            "<no error>");
  // A mirror image.
  EXPECT_THAT(LoadError(Edited("0, 0, 1, 0,  0, 0, 0, 1]", "0, 0, -1, 0,  0, 0, 0, 1]")),
              HasSubstr("cal.yaml:8: imu.T_body_imu: expected a proper rotation (det R = +1), "
                        "found det R = -1"));
  // Not an affine transform.
  EXPECT_EQ(LoadError(Edited("                 0, 0, 0, 1]", "                 0, 0, 1, 1]")),
            "cal.yaml:17: cameras.cam0.T_body_cam: expected the last row 0 0 0 1, found 0 0 1 1");
}

TEST(BoardCalibrationTest, CameraValuesAreChecked) {
  EXPECT_EQ(LoadError(Edited("[457.587, 456.134,", "[457.587, -456.134,")),
            "cal.yaml:26: cameras.cam1.intrinsics: expected focal lengths fu, fv > 0 px, found fu "
            "= 457.587, fv = -456.134");
  EXPECT_EQ(LoadError(Edited("    width_px: 752", "    width_px: 0")),
            "cal.yaml:11: cameras.cam0.width_px: expected > 0 px, found 0");
  EXPECT_EQ(LoadError(Edited("    height_px: 480", "    height_px: -480")),
            "cal.yaml:12: cameras.cam0.height_px: expected > 0 px, found -480");
  EXPECT_EQ(LoadError(Edited("    rate_hz: 20", "    rate_hz: 0")),
            "cal.yaml:13: cameras.cam0.rate_hz: expected a frame rate > 0 Hz, found 0");
  EXPECT_EQ(LoadError(Edited("    width_px: 752", "    width_px: 752.5")),
            "cal.yaml:11: cameras.cam0.width_px: expected an integer, found 752.5");
  EXPECT_EQ(LoadError(Edited("model: pinhole-radtan", "model: fisheye")),
            "cal.yaml:14: cameras.cam0.model: expected one of \"pinhole-radtan\", "
            "\"pinhole-equidistant\", found fisheye");
  EXPECT_THAT(LoadError(Edited("[-0.28340811,", "[.nan,")),
              HasSubstr("cal.yaml:16: cameras.cam0.distortion[0]: expected a finite number"));
  EXPECT_THAT(LoadError(Edited("    rate_hz: 20\n",
                               "    rate_hz: 20\n    vignetting_cos4_strength: 1.2\n")),
              HasSubstr("cameras.cam0.vignetting_cos4_strength: expected a strength in [0, 1), "
                        "found 1.2"));
}

TEST(BoardCalibrationTest, VignettingIsOptionalAndRoundTrips) {
  const BoardCalibration flat = BoardCalibration::LoadString(Edited("", ""), "cal.yaml");
  ASSERT_TRUE(flat.stereo.has_value());
  EXPECT_EQ(flat.stereo->cam0.vignetting_cos4_strength, 0.0);
  EXPECT_THAT(flat.ToYaml(), Not(HasSubstr("vignetting")));
  BoardCalibration c = flat;
  c.stereo->cam0.vignetting_cos4_strength = 0.45;
  const std::string yaml = c.ToYaml();
  EXPECT_THAT(yaml, HasSubstr("    vignetting_cos4_strength: 0.45\n"));
  ExpectBitIdentical(BoardCalibration::LoadString(yaml, "written.yaml"), c);
}

TEST(BoardCalibrationTest, ImuAndWheelValuesAreChecked) {
  EXPECT_EQ(LoadError(Edited("  rate_hz: 200", "  rate_hz: 0")),
            "cal.yaml:3: imu.rate_hz: expected a finite number > 0, found 0");
  EXPECT_EQ(LoadError(Edited("gyro_random_walk_rad_s2_sqrt_hz: 1.9393e-05",
                             "gyro_random_walk_rad_s2_sqrt_hz: -1.9393e-05")),
            "cal.yaml:5: imu.gyro_random_walk_rad_s2_sqrt_hz: expected a finite number > 0, found "
            "-1.9393e-05");
  EXPECT_EQ(LoadError(Edited("wheel_radius_m: 0.1", "wheel_radius_m: 0")),
            "cal.yaml:33: wheels.wheel_radius_m: expected a finite radius > 0 m, found 0");
}

TEST(BoardCalibrationTest, ValidateNamesTheKeyPath) {
  BoardCalibration c = BoardCalibration::LoadString(kExample, "cal.yaml");
  c.imu.T_body_imu.matrix()(3, 3) = 2.0;
  EXPECT_EQ(c.Problem()->field, "imu.T_body_imu");
  c = BoardCalibration::LoadString(kExample, "cal.yaml");
  c.wheels->lever_arm_body_m.y() = INFINITY;
  EXPECT_EQ(c.Problem()->field, "wheels.lever_arm_body_m");
  c = BoardCalibration::LoadString(kExample, "cal.yaml");
  c.stereo->cam0.height_px = 0;
  EXPECT_THROW(c.Validate(), std::invalid_argument);
  EXPECT_EQ(c.Problem()->field, "cameras.cam0.height_px");
}

TEST(BoardCalibrationTest, CameraInImuFrameIsTheImuInverseTimesTheCamera) {
  BoardCalibration c = BoardCalibration::LoadString(kExample, "cal.yaml");
  c.imu.T_body_imu.linear() =
      Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  c.imu.T_body_imu.translation() = Eigen::Vector3d(0.1, -0.2, 0.05);
  const CameraModel in_imu = CameraInImuFrame(c.stereo->cam0, c.imu);
  // The exact expression roverd and rover-eval used, bit for bit.
  const Eigen::Isometry3d T_imu_body = c.imu.T_body_imu.inverse();
  const Eigen::Isometry3d expected = T_imu_body * c.stereo->cam0.T_body_cam;
  for (int i = 0; i < 16; ++i) {
    EXPECT_EQ(std::bit_cast<uint64_t>(in_imu.T_body_cam.matrix()(i / 4, i % 4)),
              std::bit_cast<uint64_t>(expected.matrix()(i / 4, i % 4)));
  }
  CameraModel same = in_imu;
  same.T_body_cam = c.stereo->cam0.T_body_cam;
  EXPECT_EQ(same, c.stereo->cam0);
  // A point seen by the camera is the same point in the IMU frame.
  const Eigen::Vector3d p_cam(0.3, -0.1, 2.0);
  EXPECT_LT(
      (in_imu.T_body_cam * p_cam - c.imu.T_body_imu.inverse() * (c.stereo->cam0.T_body_cam * p_cam))
          .norm(),
      1e-12);
}

}  // namespace
}  // namespace rover::calib
