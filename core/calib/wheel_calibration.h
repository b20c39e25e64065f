#ifndef ROVER_CORE_CALIB_WHEEL_CALIBRATION_H_
#define ROVER_CORE_CALIB_WHEEL_CALIBRATION_H_

// The wheel-odometry calibration of a skid-steered rover: the geometry that
// turns the drives' wheel speeds into a body velocity, and the wheel-terrain
// figures (yaw scrub, slip against tilt) a field calibration finds.
//
// The same keys make the `wheels` section of the board calibration file
// (board_calibration.h) and a dataset's mav0/can0/sensor.yaml:
//
//   wheel_radius_m: 0.1
//   track_m: 0.5
//   lever_arm_body_m: [0, 0, -0.25]
//   nonholonomic_point_body_m: [0, 0, -0.35]   # optional: the contact centre
//                                                # under the lever arm
//   yaw_scrub_factor: 1.3                        # optional: 1 (ideal wheels)
//   slip_ratio_base: 0.02                        # optional: 0 (no slip)
//   slip_ratio_per_tilt_rad: 0.1                 # optional: 0

#include <Eigen/Core>
#include <optional>
#include <string>

#include "core/calib/validation.h"
#include "core/config/config.h"

namespace rover::calib {

/// Wheel geometry. A board or dataset without wheel drives has none
/// (BoardCalibration::wheels is then empty).
struct WheelCalibration {
  double wheel_radius_m = 0.0;
  /// Distance between the left and right wheel contact lines.
  double track_m = 0.0;
  /// Mean of the wheel centres in the body frame: where the wheel-odometry
  /// velocity is measured.
  Eigen::Vector3d lever_arm_body_m = Eigen::Vector3d::Zero();
  /// The point without sideways velocity (the non-holonomic constraint), in
  /// the body frame: on a real rover the centre of the wheel contacts.
  Eigen::Vector3d nonholonomic_point_body_m = Eigen::Vector3d::Zero();
  /// Skid steering: the wheel-speed difference over the ideal one in a turn.
  double yaw_scrub_factor = 1.0;
  /// Longitudinal slip s = base + per_tilt * tilt (tilt: body z from vertical).
  double slip_ratio_base = 0.0;
  double slip_ratio_per_tilt_rad = 0.0;

  /// Reads the keys above from `node`; optional keys take the defaults shown
  /// there. Throws ConfigError "file:line: key: expected ..., found ..." for a
  /// missing, malformed or unusable value (Problem()); the caller checks for
  /// unknown keys.
  static WheelCalibration Load(const ConfigNode& node);

  /// The keys as YAML lines indented by `indent` spaces, every number in its
  /// shortest round-trip form (Load() reads them back exactly).
  std::string ToYaml(int indent = 0) const;

  /// The first unusable field (named as the member) and why, or nullopt:
  /// radius and track finite and > 0, points finite, scrub factor finite and
  /// > 0, slip figures finite.
  std::optional<FieldProblem> Problem() const;

  /// Exact equality of every field.
  friend bool operator==(const WheelCalibration& a, const WheelCalibration& b) {
    return a.wheel_radius_m == b.wheel_radius_m && a.track_m == b.track_m &&
           a.lever_arm_body_m == b.lever_arm_body_m &&
           a.nonholonomic_point_body_m == b.nonholonomic_point_body_m &&
           a.yaw_scrub_factor == b.yaw_scrub_factor && a.slip_ratio_base == b.slip_ratio_base &&
           a.slip_ratio_per_tilt_rad == b.slip_ratio_per_tilt_rad;
  }
};

}  // namespace rover::calib

#endif  // ROVER_CORE_CALIB_WHEEL_CALIBRATION_H_
