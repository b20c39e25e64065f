#ifndef ROVER_DRIVERS_IMU_IMU_DEVICE_ERROR_H_
#define ROVER_DRIVERS_IMU_IMU_DEVICE_ERROR_H_

#include <stdexcept>

namespace rover::drivers {

/// Start-up failure of an IMU driver or of the port under it (serial TTY,
/// spidev): the message names the device path, the step that failed, what
/// was expected and, where there is one, the system error (strerror). Never
/// thrown from Read(): the real-time path reports through ReadStatus and the
/// driver's health counters instead.
class ImuDeviceError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace rover::drivers

#endif  // ROVER_DRIVERS_IMU_IMU_DEVICE_ERROR_H_
