#ifndef ROVER_FIRMWARE_ROVERD_SENSOR_CALIBRATION_H_
#define ROVER_FIRMWARE_ROVERD_SENSOR_CALIBRATION_H_

// The IMU's calibration (EuRoC sensor.yaml: a dataset's, or a board's
// calibration folder) as roverd's filter options. Shared by the replay and
// hardware boards, which hand the VO their cameras through
// calib::CameraInImuFrame.

#include <string>

#include "core/calib/imu_calibration.h"
#include "estimator/eskf/eskf_options.h"

namespace rover::roverd {

/// The filter's options: the EskfOptions file at `path` if given (complete;
/// absent keys take the defaults), else the defaults with the IMU's own
/// noise figures and wheels off. The rate always comes from the IMU.
estimator::EskfOptions FilterOptionsFromCalibration(const calib::ImuCalibration& imu,
                                                    const std::string& path);

}  // namespace rover::roverd

#endif  // ROVER_FIRMWARE_ROVERD_SENSOR_CALIBRATION_H_
