#ifndef ROVER_FIRMWARE_ROVERD_SENSOR_CALIBRATION_H_
#define ROVER_FIRMWARE_ROVERD_SENSOR_CALIBRATION_H_

// The sensors' calibration (EuRoC sensor.yaml: a dataset's, or a board's
// calibration folder) as roverd's filter and VO options. Shared by the
// replay and hardware boards.

#include <string>

#include <Eigen/Geometry>

#include "core/calib/camera_model.h"
#include "core/calib/imu_calibration.h"
#include "estimator/eskf/eskf_options.h"

namespace rover::roverd {

/// A camera's calibration as the VO's camera model, with T_body_cam
/// expressed in the filter's body frame (the IMU frame): `T_imu_body` is
/// the inverse of the IMU's T_body_imu.
calib::CameraModel ToCameraModel(const calib::CameraModel& c, const Eigen::Isometry3d& T_imu_body);

/// The filter's options: the EskfOptions file at `path` if given (complete;
/// absent keys take the defaults), else the defaults with the IMU's own
/// noise figures and wheels off. The rate always comes from the IMU.
estimator::EskfOptions FilterOptionsFromCalibration(const calib::ImuCalibration& imu,
                                                    const std::string& path);

}  // namespace rover::roverd

#endif  // ROVER_FIRMWARE_ROVERD_SENSOR_CALIBRATION_H_
