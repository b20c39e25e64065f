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
  /// Starts the sample stream, once, just before the IMU loop reads it
  /// (start-up: may block and throw). A device that streams into a small
  /// kernel buffer (a serial line holds about 2 s at 400 Hz) must not start
  /// while the rest of the process is still opening devices, or the start
  /// of the stream is lost. Default: the stream needs no start.
  virtual void Start() {}
  /// Waits up to `timeout` for the next sample.
  virtual ReadStatus Read(ImuSample* sample, Duration timeout) = 0;
};

}  // namespace rover::drivers

#endif  // ROVER_DRIVERS_IMU_IMU_DRIVER_H_
