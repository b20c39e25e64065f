#ifndef ROVER_FIRMWARE_RUNTIME_BOARD_BOARD_HARDWARE_OPTIONS_H_
#define ROVER_FIRMWARE_RUNTIME_BOARD_BOARD_HARDWARE_OPTIONS_H_

// `hardware:` of a board profile (board.profile: hardware): which real
// devices roverd opens and how. Plain settings only; firmware/roverd's
// HardwareBoard turns them into the drivers' own options.
//
//   hardware:
//     calibration: /etc/rover/calibration.yaml  # board calibration file, or an EuRoC folder
//     estimator_config: ""                 # EskfOptions YAML; "" = defaults + imu0's noise
//     vo_config: ""                        # StereoOdometryOptions YAML; "" = defaults
//     imu: {driver: xsens, device: /dev/ttyUSB0, rate_hz: 400, baud_rate: 921600}
//     camera:                              # absent: no stereo head (no VO)
//       driver: v4l2                       # v4l2 | aravis
//       cam0: /dev/video0                  # v4l2: node; aravis: device id, serial or IPv4
//       cam1: /dev/video1
//       width_px: 752, height_px: 480, pixel_format: GREY, rate_hz: 10
//       trigger: {chip: gpiochip0, line: 17, pulse_width_s: 0.001}   # absent: free running
//     can: {interface: can0}               # absent: no wheel odometry

#include <optional>
#include <string>
#include <utility>

#include "core/config/config.h"

namespace rover::runtime {

enum class ImuDriverKind { kXsens, kAdis16448 };
enum class CameraDriverKind { kV4l2, kAravis };

/// `hardware.imu`.
struct BoardImuOptions {
  ImuDriverKind driver = ImuDriverKind::kXsens;
  /// xsens: the serial port (/dev/ttyUSB0, /dev/ttyTHS1, a pty);
  /// adis16448: the spidev node (/dev/spidev0.0).
  std::string device;
  /// Output rate: xsens in [1, 2000] (400 usual); adis16448 409.6 or 819.2.
  double rate_hz = 400.0;
  /// xsens: the UART's rate, as configured in the device.
  int baud_rate = 921600;
  /// adis16448: the data-ready line (chip path, name or label; offset).
  std::string data_ready_chip = "gpiochip0";
  int data_ready_line = 27;
};

/// `hardware.camera.trigger`: the stereo head's GPIO trigger output.
struct BoardTriggerOptions {
  std::string chip = "gpiochip0";
  int line = 17;
  double pulse_width_s = 0.001;
  bool active_low = false;
};

/// `hardware.camera`: two identical cameras triggered together.
struct BoardCameraOptions {
  CameraDriverKind driver = CameraDriverKind::kV4l2;
  std::string cam0;
  std::string cam1;
  int width_px = 752;
  int height_px = 480;
  /// v4l2: GREY | Y16 | YUYV | MJPG; aravis: Mono8 | Mono16.
  std::string pixel_format = "GREY";
  /// Trigger rate (or free-running rate without a trigger), in [1, 100].
  double rate_hz = 10.0;
  /// Exposure time; 0 keeps the camera's own setting.
  double exposure_us = 0.0;
  int buffers = 4;
  /// Two frames pair when their stamps differ by at most this much, s.
  double pair_tolerance_s = 0.002;
  std::optional<BoardTriggerOptions> trigger;
};

/// `hardware.can`.
struct BoardCanOptions {
  std::string interface = "can0";
};

struct BoardHardwareOptions {
  /// The board's calibration: a board calibration file (core/calib format)
  /// or a folder with imu0/ and, with a camera, cam0/ and cam1/ (and, for
  /// wheel odometry, can0/) sensor.yaml in the EuRoC layout
  /// (calib::LoadBoardCalibration).
  std::string calibration;
  std::string estimator_config{};
  std::string vo_config{};
  BoardImuOptions imu;
  std::optional<BoardCameraOptions> camera;
  std::optional<BoardCanOptions> can;

  /// Reads `node` (the hardware: map), validated; throws ConfigError at the
  /// offending key.
  static BoardHardwareOptions Load(const ConfigNode& node);
  /// The first problem as ("hardware.<key>", "expected ..., found ..."), if
  /// any.
  std::optional<std::pair<std::string, std::string>> Problem() const;
};

}  // namespace rover::runtime

#endif  // ROVER_FIRMWARE_RUNTIME_BOARD_BOARD_HARDWARE_OPTIONS_H_
