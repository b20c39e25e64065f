#ifndef ROVER_CORE_CALIB_WHEEL_CALIBRATION_H_
#define ROVER_CORE_CALIB_WHEEL_CALIBRATION_H_

// The wheel-odometry geometry of a skid-steered rover: what turns the drives'
// wheel speeds into a body velocity.

#include <Eigen/Core>
#include <optional>

#include "core/calib/validation.h"

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

  /// The first unusable field (named as the member) and why, or nullopt:
  /// radius and track finite and > 0, lever arm finite.
  std::optional<FieldProblem> Problem() const;

  /// Exact equality of every field.
  friend bool operator==(const WheelCalibration& a, const WheelCalibration& b) {
    return a.wheel_radius_m == b.wheel_radius_m && a.track_m == b.track_m &&
           a.lever_arm_body_m == b.lever_arm_body_m;
  }
};

}  // namespace rover::calib

#endif  // ROVER_CORE_CALIB_WHEEL_CALIBRATION_H_
