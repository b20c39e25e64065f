#ifndef ROVER_DRIVERS_IMU_IMU_SAMPLE_H_
#define ROVER_DRIVERS_IMU_IMU_SAMPLE_H_

#include <Eigen/Core>
#include <cstdint>

#include "core/time/time.h"

namespace rover::drivers {

/// One IMU reading in the IMU (body) frame, as every IMU driver delivers it:
/// hardware, simulated, or replayed from a dataset or a log.
struct ImuSample {
  Time stamp;             ///< sample time on CLOCK_MONOTONIC
  uint64_t sequence = 0;  ///< increments by one per sample; gaps mean lost samples
  Eigen::Vector3d angular_velocity_rad_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d linear_acceleration_m_s2 = Eigen::Vector3d::Zero();
};

}  // namespace rover::drivers

#endif  // ROVER_DRIVERS_IMU_IMU_SAMPLE_H_
