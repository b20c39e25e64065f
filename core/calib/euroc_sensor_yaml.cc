#include "core/calib/euroc_sensor_yaml.h"

#include <opencv2/core.hpp>

#include <algorithm>
#include <filesystem>
#include <vector>

#include "core/config/config.h"

namespace rover::calib {
namespace {

namespace fs = std::filesystem;

cv::FileStorage OpenYaml(const std::string& path) {
  if (!fs::exists(path)) throw CalibrationError(path + ": missing");
  try {
    cv::FileStorage storage(path, cv::FileStorage::READ);
    if (!storage.isOpened()) throw CalibrationError(path + ": cannot parse as YAML");
    return storage;
  } catch (const cv::Exception& e) {
    throw CalibrationError(path + ": cannot parse as YAML: " + e.msg);
  }
}

std::vector<double> Numbers(const cv::FileStorage& fs, const std::string& path, const char* key,
                            std::size_t expected) {
  std::vector<double> values;
  const cv::FileNode node = fs[key];
  if (node.isSeq()) node >> values;
  if (values.size() != expected) {
    throw CalibrationError(path + ": " + key + ": expected " + std::to_string(expected) +
                           " numbers, found " + std::to_string(values.size()));
  }
  return values;
}

Eigen::Isometry3d ReadTbs(const cv::FileStorage& fs, const std::string& path) {
  std::vector<double> data;
  const cv::FileNode node = fs["T_BS"]["data"];
  if (node.isSeq()) node >> data;
  if (data.size() != 16) {
    throw CalibrationError(path + ": T_BS.data: expected 16 numbers (4x4 row-major), found " +
                           std::to_string(data.size()));
  }
  Eigen::Matrix4d m;
  for (int r = 0; r < 4; ++r) {
    for (int col = 0; col < 4; ++col) m(r, col) = data[static_cast<std::size_t>(4 * r + col)];
  }
  const Eigen::Matrix3d R = m.topLeftCorner<3, 3>();
  if ((R.transpose() * R - Eigen::Matrix3d::Identity()).norm() > 1e-4) {
    throw CalibrationError(path + ": T_BS: rotation part is not orthonormal");
  }
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  // Re-orthonormalise: published calibrations carry ~1e-6 rounding.
  T.linear() = Eigen::Quaterniond(R).normalized().toRotationMatrix();
  T.translation() = m.topRightCorner<3, 1>();
  return T;
}

double ReadDouble(const cv::FileStorage& fs, const std::string& path, const char* key) {
  const cv::FileNode node = fs[key];
  if (!node.isReal() && !node.isInt()) {
    throw CalibrationError(path + ": " + key + ": expected a number");
  }
  return static_cast<double>(node);
}

}  // namespace

CameraModel LoadEurocCamera(const std::string& path) {
  const cv::FileStorage fs = OpenYaml(path);
  CameraModel c;
  const std::vector<double> resolution = Numbers(fs, path, "resolution", 2);
  c.width_px = static_cast<int>(resolution[0]);
  c.height_px = static_cast<int>(resolution[1]);
  c.rate_hz = ReadDouble(fs, path, "rate_hz");
  const std::string model = static_cast<std::string>(fs["camera_model"]);
  const std::string distortion = static_cast<std::string>(fs["distortion_model"]);
  if (model == "pinhole" && distortion == EurocDistortionName(DistortionModel::kRadialTangential)) {
    c.distortion_model = DistortionModel::kRadialTangential;
  } else if (model == "pinhole" &&
             distortion == EurocDistortionName(DistortionModel::kEquidistant)) {
    c.distortion_model = DistortionModel::kEquidistant;
  } else {
    throw CalibrationError(path +
                           ": expected camera_model pinhole with distortion_model "
                           "radial-tangential or equidistant, found '" +
                           model + "' / '" + distortion + "'");
  }
  const std::vector<double> k = Numbers(fs, path, "intrinsics", 4);
  const std::vector<double> d = Numbers(fs, path, "distortion_coefficients", 4);
  std::copy(k.begin(), k.end(), c.intrinsics.begin());
  std::copy(d.begin(), d.end(), c.distortion.begin());
  c.T_body_cam = ReadTbs(fs, path);
  // Not a EuRoC key: this project's extension (absent: a flat field).
  if (!fs["vignetting_cos4_strength"].empty()) {
    c.vignetting_cos4_strength = ReadDouble(fs, path, "vignetting_cos4_strength");
  }
  return c;
}

ImuCalibration LoadEurocImu(const std::string& path) {
  const cv::FileStorage fs = OpenYaml(path);
  ImuCalibration c;
  c.rate_hz = ReadDouble(fs, path, "rate_hz");
  c.gyro_noise_density_rad_s_sqrt_hz = ReadDouble(fs, path, "gyroscope_noise_density");
  c.gyro_random_walk_rad_s2_sqrt_hz = ReadDouble(fs, path, "gyroscope_random_walk");
  c.accel_noise_density_m_s2_sqrt_hz = ReadDouble(fs, path, "accelerometer_noise_density");
  c.accel_random_walk_m_s3_sqrt_hz = ReadDouble(fs, path, "accelerometer_random_walk");
  c.T_body_imu = ReadTbs(fs, path);
  return c;
}

WheelCalibration LoadEurocWheels(const std::string& sensor_yaml) {
  try {
    const ConfigNode root = ConfigNode::LoadFile(sensor_yaml);
    const std::string type = root.Get<std::string>("sensor_type");
    if (type != kWheelSensorType) {
      root.Fail("sensor_type",
                "expected " + std::string(kWheelSensorType) + ", found '" + type + "'");
    }
    (void)root.Get<std::string>("comment", "");
    const WheelCalibration c = WheelCalibration::Load(root);
    root.CheckNoUnknownKeysRecursive();
    return c;
  } catch (const ConfigError& e) {
    throw CalibrationError(e.what());
  }
}

std::string EurocWheelsYaml(const WheelCalibration& wheels, const std::string& comment) {
  return "sensor_type: " + std::string(kWheelSensorType) + "\ncomment: " + comment + "\n" +
         wheels.ToYaml();
}

namespace {

// The sensors of an EuRoC-layout folder; without `cameras_required`, a
// folder without cam0/ and cam1/ is a board without a stereo head.
BoardCalibration LoadEurocFolder(const fs::path& dir, bool cameras_required) {
  BoardCalibration c;
  c.imu = LoadEurocImu((dir / "imu0/sensor.yaml").string());
  const fs::path cam0 = dir / "cam0/sensor.yaml", cam1 = dir / "cam1/sensor.yaml";
  if (cameras_required || fs::exists(cam0) || fs::exists(cam1)) {
    c.stereo = StereoCalibration{LoadEurocCamera(cam0.string()), LoadEurocCamera(cam1.string())};
  }
  const fs::path wheels = dir / "can0/sensor.yaml";
  if (fs::exists(wheels)) c.wheels = LoadEurocWheels(wheels.string());
  return c;
}

}  // namespace

BoardCalibration LoadEurocCalibration(const std::string& mav0_dir) {
  return LoadEurocFolder(mav0_dir, true);
}

BoardCalibration LoadBoardCalibration(const std::string& path) {
  if (fs::is_directory(path)) return LoadEurocFolder(path, false);
  if (!fs::is_regular_file(path)) {
    throw CalibrationError(path +
                           ": expected a board calibration file or an EuRoC calibration "
                           "folder (imu0/ cam0/ cam1/), found nothing there");
  }
  try {
    return BoardCalibration::LoadFile(path);
  } catch (const ConfigError& e) {
    throw CalibrationError(e.what());
  }
}

}  // namespace rover::calib
