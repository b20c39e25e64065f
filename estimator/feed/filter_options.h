#ifndef ROVER_ESTIMATOR_FEED_FILTER_OPTIONS_H_
#define ROVER_ESTIMATOR_FEED_FILTER_OPTIONS_H_

// The one rule that turns a board's calibration into the filter's and the
// VO's options. roverd (hardware and replay boards), the simulator and
// `rover-eval vio` all call it, so the same calibration and the same option
// file give the same filter everywhere.

#include <string>

#include "core/calib/board_calibration.h"
#include "estimator/eskf/eskf_options.h"
#include "estimator/vo/stereo_odometry_options.h"

namespace rover::estimator {

/// The filter's options for a board:
///   1. the EskfOptions defaults;
///   2. the IMU's rate and noise densities from `calibration.imu` (each one
///      that is positive);
///   3. wheel odometry on, with the geometry and wheel-terrain figures of
///      `calibration.wheels`, when the calibration has wheels; off otherwise;
///   4. room for kMaxClones clones (the VO's keyframes plus frames in flight);
///   5. then every key that the EskfOptions YAML file `filter_config_path`
///      (if not empty) sets overrides the above; keys it leaves out keep them.
/// Throws ConfigError naming file:line:key for a bad file.
EskfOptions FilterOptionsFromCalibration(const calib::BoardCalibration& calibration,
                                         const std::string& filter_config_path = "");

/// The VO's options: the defaults with checks.nominal_rate_hz set to
/// `camera_rate_hz` (when positive, so dropped frames are counted), then
/// every key of the StereoOdometryOptions YAML file `vo_config_path` (if not
/// empty). Throws ConfigError for a bad file, std::invalid_argument for bad
/// values.
vo::StereoOdometryOptions VoOptionsFromCalibration(double camera_rate_hz,
                                                   const std::string& vo_config_path = "");

}  // namespace rover::estimator

#endif  // ROVER_ESTIMATOR_FEED_FILTER_OPTIONS_H_
