#ifndef ROVER_CORE_CALIB_BOARD_CALIBRATION_H_
#define ROVER_CORE_CALIB_BOARD_CALIBRATION_H_

// A board's whole calibration (IMU, optional stereo head, optional wheels)
// and its one file format:
//
//   # rover board calibration (format 1)
//   format: rover-calibration-1
//   imu:
//     rate_hz: 200
//     gyro_noise_density_rad_s_sqrt_hz: 0.00016968
//     gyro_random_walk_rad_s2_sqrt_hz: 1.9393e-05
//     accel_noise_density_m_s2_sqrt_hz: 0.002
//     accel_random_walk_m_s3_sqrt_hz: 0.003
//     T_body_imu: [1, 0, 0, 0,  0, 1, 0, 0,  0, 0, 1, 0,  0, 0, 0, 1]  # row-major 4x4
//   cameras:                                   # optional: a board without a stereo head
//     cam0:
//       width_px: 752
//       height_px: 480
//       rate_hz: 20
//       model: pinhole-radtan                  # or pinhole-equidistant
//       intrinsics: [458.654, 457.296, 367.215, 248.375]  # fu, fv, cu, cv [px]
//       distortion: [-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05]
//       T_body_cam: [0.0148655429818, -0.999880929698, 0.00414029679422, -0.0216401454975,
//                    0.999557249008, 0.0149672133247, 0.025715529948, -0.064676986768,
//                    -0.0257744366974, 0.00375618835797, 0.999660727178, 0.00981073058949,
//                    0, 0, 0, 1]
//     cam1: {...}                              # the same keys
//   wheels:                                    # optional: a board without wheel drives
//     wheel_radius_m: 0.1
//     track_m: 0.5
//     lever_arm_body_m: [0, 0, -0.25]
//     nonholonomic_point_body_m: [0, 0, -0.35]  # the wheel-terrain keys are
//     yaw_scrub_factor: 1.3                      # optional (wheel_calibration.h)
//     slip_ratio_base: 0.02
//     slip_ratio_per_tilt_rad: 0.1
//
// Every key shown is required within its section; unknown keys are errors.
// `distortion` is k1 k2 p1 p2 for pinhole-radtan and k1 k2 k3 k4 for
// pinhole-equidistant (see DistortionModel). A T_ is 16 numbers, row-major
// (or four rows of four), and must be a rigid transform (rotation
// orthonormal within 1e-6, det +1, last row 0 0 0 1); it is used as written,
// never re-orthonormalised, so a file reads back bit for bit.
//
// ToYaml() writes every number in its shortest round-trip form
// (std::to_chars), so LoadString(c.ToYaml()) == c exactly.

#include <optional>
#include <string>
#include <string_view>

#include "core/calib/camera_model.h"
#include "core/calib/imu_calibration.h"
#include "core/calib/validation.h"
#include "core/calib/wheel_calibration.h"
#include "core/config/config.h"

namespace rover::calib {

/// The value of the `format` key this code reads and writes.
inline constexpr std::string_view kBoardCalibrationFormat = "rover-calibration-1";

/// The two cameras of a stereo head (cam0 left, cam1 right).
struct StereoCalibration {
  CameraModel cam0;
  CameraModel cam1;

  friend bool operator==(const StereoCalibration&, const StereoCalibration&) = default;
};

/// Everything calibrated on one board.
struct BoardCalibration {
  ImuCalibration imu;
  std::optional<StereoCalibration> stereo;  ///< the `cameras` section
  std::optional<WheelCalibration> wheels;   ///< the `wheels` section

  /// Reads the file at `path` (the format above) and rejects unknown keys.
  /// Throws ConfigError "path:line: key.path: expected ..., found ..." for
  /// anything it cannot use, including values Problem() would report.
  static BoardCalibration LoadFile(const std::string& path);

  /// As LoadFile, for text in memory; `source_name` stands in for the file
  /// name in error messages.
  static BoardCalibration LoadString(std::string_view yaml, std::string source_name);

  /// Reads the keys of `node` (format, imu, cameras, wheels), e.g. a section
  /// of a larger document. Unknown keys are left to the caller's
  /// CheckNoUnknownKeysRecursive() (LoadFile and LoadString call it).
  static BoardCalibration Load(const ConfigNode& node);

  /// The calibration in the format above; numbers in shortest round-trip form.
  std::string ToYaml() const;

  /// Validates (as Validate()), then writes ToYaml() to `path` through a
  /// temporary file renamed into place, so a reader never sees half a file.
  /// Throws std::invalid_argument for an invalid calibration and
  /// std::runtime_error naming the path if it cannot be written.
  void SaveFile(const std::string& path) const;

  /// The first unusable value, with `field` as its key path in the file
  /// ("imu.T_body_imu", "cameras.cam1.intrinsics", "wheels.track_m"), or
  /// nullopt.
  std::optional<FieldProblem> Problem() const;

  /// Throws std::invalid_argument "key.path: expected ..., found ..." if
  /// Problem() finds one.
  void Validate() const;

  friend bool operator==(const BoardCalibration&, const BoardCalibration&) = default;
};

/// The camera with T_body_cam re-expressed in the filter's body frame, which
/// is the IMU frame: T_imu_cam = T_body_imu^-1 * T_body_cam. Every other field
/// is copied.
CameraModel CameraInImuFrame(const CameraModel& camera, const ImuCalibration& imu);

}  // namespace rover::calib

#endif  // ROVER_CORE_CALIB_BOARD_CALIBRATION_H_
