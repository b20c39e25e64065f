#ifndef ROVER_CORE_CALIB_EUROC_SENSOR_YAML_H_
#define ROVER_CORE_CALIB_EUROC_SENSOR_YAML_H_

// Readers for the calibration files of the EuRoC/ASL dataset layout
// (mav0/<sensor>/sensor.yaml, OpenCV FileStorage YAML with a %YAML:1.0
// header), which datasets, `rover-sim generate` and board calibration
// folders use:
//
//   camera: resolution [w, h], rate_hz, camera_model pinhole,
//           intrinsics [fu, fv, cu, cv], distortion_model radial-tangential
//           or equidistant, distortion_coefficients [4], T_BS
//   IMU:    rate_hz, gyroscope_noise_density, gyroscope_random_walk,
//           accelerometer_noise_density, accelerometer_random_walk, T_BS
//   wheels: (mav0/can0/sensor.yaml, our addition; plain YAML, no header)
//           sensor_type wheel_drives, comment, and the keys of
//           WheelCalibration (wheel_calibration.h)
//
// T_BS (`data`: 16 numbers, row-major) is the sensor's pose in the body
// frame. Its rotation must be orthonormal within 1e-4 and is then
// re-orthonormalised, because published calibrations carry ~1e-6 rounding.

#include <stdexcept>
#include <string>
#include <string_view>

#include "core/calib/board_calibration.h"
#include "core/calib/camera_model.h"
#include "core/calib/imu_calibration.h"
#include "core/calib/wheel_calibration.h"

namespace rover::calib {

/// A sensor.yaml that is missing or unusable; the message starts with the
/// file's path and names the key.
class CalibrationError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Reads an EuRoC camera sensor.yaml. Throws CalibrationError.
CameraModel LoadEurocCamera(const std::string& sensor_yaml);

/// Reads an EuRoC IMU sensor.yaml. Throws CalibrationError.
ImuCalibration LoadEurocImu(const std::string& sensor_yaml);

/// The sensor_type of a wheel-drive sensor.yaml.
inline constexpr std::string_view kWheelSensorType = "wheel_drives";

/// Reads a wheel-drive sensor.yaml (mav0/can0/sensor.yaml). Throws
/// CalibrationError "path:line: key: expected ..., found ...".
WheelCalibration LoadEurocWheels(const std::string& sensor_yaml);

/// The text of a wheel-drive sensor.yaml, which LoadEurocWheels() reads back
/// exactly.
std::string EurocWheelsYaml(const WheelCalibration& wheels, const std::string& comment);

/// Reads `mav0_dir`/imu0, cam0 and cam1 sensor.yaml (in that order) into one
/// calibration with a stereo head, and the wheels from can0/sensor.yaml when
/// it exists. Throws CalibrationError.
BoardCalibration LoadEurocCalibration(const std::string& mav0_dir);

/// A board's calibration from `path`: a board calibration file
/// (board_calibration.h), or a folder in the EuRoC layout (imu0/, and
/// cam0/ + cam1/ for a stereo head, can0/ for wheel drives: sensor.yaml each). Throws
/// CalibrationError naming the file (and line and key) it cannot use.
BoardCalibration LoadBoardCalibration(const std::string& path);

}  // namespace rover::calib

#endif  // ROVER_CORE_CALIB_EUROC_SENSOR_YAML_H_
