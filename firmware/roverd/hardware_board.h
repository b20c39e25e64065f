#ifndef ROVER_FIRMWARE_ROVERD_HARDWARE_BOARD_H_
#define ROVER_FIRMWARE_ROVERD_HARDWARE_BOARD_H_

// Board profile `hardware`: the board's real devices as roverd's sensors,
// through the same driver interfaces the simulator and replay implement.
//   IMU     Xsens MTi over a raw TTY (Xbus), or ADIS16448 over spidev with
//           its data-ready line through libgpiod
//   camera  two V4L2 or two Aravis (GigE Vision / USB3 Vision) cameras,
//           paired by StereoPairer; optionally triggered by a GPIO line
//   CAN     the wheel drives on a SocketCAN interface, with the wheel
//           protocol's kernel filters
// The filter and VO are configured from the board's calibration folder
// (imu0/, cam0/, cam1/ sensor.yaml, the EuRoC format) and its optional
// estimator / VO files. Every device is opened and configured here, before
// the real-time threads start; a device that is missing or refuses its
// configuration throws, naming the device and the setting.

#include <memory>

#include "drivers/camera/mono_camera.h"
#include "drivers/camera/stereo_camera_driver.h"
#include "drivers/camera/stereo_pairer.h"
#include "drivers/can/socket_can_bus.h"
#include "drivers/gpio/gpio_chip.h"
#include "drivers/gpio/gpio_edge_source.h"
#include "drivers/imu/imu_driver.h"
#include "drivers/imu/spi_device.h"
#include "firmware/roverd/roverd.h"
#include "firmware/runtime/board/board_hardware_options.h"

namespace rover::roverd {

class HardwareBoard {
 public:
  /// Loads the calibration and opens every device of `options`. Throws
  /// (drivers' errors, calib::CalibrationError, ConfigError,
  /// std::invalid_argument) naming the device or file and the problem.
  explicit HardwareBoard(const runtime::BoardHardwareOptions& options);
  ~HardwareBoard();
  HardwareBoard(const HardwareBoard&) = delete;
  HardwareBoard& operator=(const HardwareBoard&) = delete;

  /// The drivers; camera, trigger and CAN are null when not configured.
  RoverdDrivers drivers();
  /// Estimator and camera set-up from the calibration; real time.
  const RoverdOptions& options() const { return options_; }
  /// One line per device opened, for the start-up log.
  const std::string& description() const { return description_; }
  /// The devices' own counters, a line per device group, for the exit
  /// summary: stereo pairing per camera, the CAN bus. Call after roverd's
  /// threads have stopped.
  std::string DeviceReport() const;

 private:
  void OpenImu(const runtime::BoardImuOptions& imu);
  void OpenCameras(const runtime::BoardCameraOptions& camera);
  void OpenCan(const runtime::BoardCanOptions& can);

  RoverdOptions options_;
  std::string description_;
  // The devices, in the order they are opened (and closed in reverse).
  std::unique_ptr<drivers::MonoCamera> cam0_;
  std::unique_ptr<drivers::MonoCamera> cam1_;
  std::unique_ptr<drivers::StereoPairer> stereo_;
  std::unique_ptr<drivers::GpioChip> trigger_chip_;
  std::unique_ptr<drivers::CameraTrigger> trigger_;
  std::unique_ptr<drivers::SocketCanBus> can_;
  std::unique_ptr<drivers::GpioChip> data_ready_chip_;
  std::unique_ptr<drivers::GpioEdgeSource> data_ready_;
  std::unique_ptr<drivers::SpiDevice> spi_;
  std::unique_ptr<drivers::ImuDriver> imu_;
};

}  // namespace rover::roverd

#endif  // ROVER_FIRMWARE_ROVERD_HARDWARE_BOARD_H_
