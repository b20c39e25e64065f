#ifndef ROVER_DRIVERS_IMU_IMU_DRIVER_H_
#define ROVER_DRIVERS_IMU_IMU_DRIVER_H_

#include "core/time/time.h"
#include "drivers/imu/imu_sample.h"
#include "drivers/read_status.h"

namespace rover::drivers {

/// An IMU as roverd's IMU thread sees it. Implementations: the Xsens and SPI
/// drivers, the simulator, and dataset/log replay. Read() is called from the
/// real-time thread: after Start() it must not allocate or take locks, and it
/// blocks at most `timeout`.
class ImuDriver {
 public:
  virtual ~ImuDriver() = default;
  /// Waits up to `timeout` for the next sample.
  virtual ReadStatus Read(ImuSample* sample, Duration timeout) = 0;
};

}  // namespace rover::drivers

#endif  // ROVER_DRIVERS_IMU_IMU_DRIVER_H_
