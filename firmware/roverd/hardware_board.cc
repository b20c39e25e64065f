#include "firmware/roverd/hardware_board.h"

#include <cstdio>
#include <stdexcept>

#include "core/calib/board_calibration.h"
#include "core/calib/euroc_sensor_yaml.h"
#include "drivers/camera/aravis_camera.h"
#include "drivers/camera/stereo_pairer.h"
#include "drivers/camera/v4l2_camera.h"
#include "drivers/gpio/gpio_camera_trigger.h"
#include "drivers/gpio/gpio_line_edge_source.h"
#include "drivers/gpio/libgpiod_chip.h"
#include "drivers/imu/adis16448_driver.h"
#include "drivers/imu/spidev_device.h"
#include "drivers/imu/xsens_mti_driver.h"
#include "estimator/feed/filter_options.h"

namespace rover::roverd {
namespace {

// "400 Hz", "409.6 Hz": rates as a user wrote them.
std::string Hz(double rate_hz) {
  char text[32];
  std::snprintf(text, sizeof text, "%g Hz", rate_hz);
  return text;
}

/// The board's calibration (hardware.calibration: a board calibration file
/// or an EuRoC calibration folder); with a stereo head it must calibrate both
/// cameras at the image size they are set to: the intrinsics of another size
/// would be silently wrong.
calib::BoardCalibration LoadCalibration(const runtime::BoardHardwareOptions& options) {
  calib::BoardCalibration c;
  try {
    c = calib::LoadBoardCalibration(options.calibration);
  } catch (const calib::CalibrationError& e) {
    throw std::invalid_argument(std::string("hardware.calibration: ") + e.what());
  }
  if (!options.camera) return c;
  if (!c.stereo) {
    throw std::invalid_argument("hardware.calibration: expected cam0 and cam1 in " +
                                options.calibration + " (hardware.camera is set), found none");
  }
  const runtime::BoardCameraOptions& camera = *options.camera;
  for (const calib::CameraModel* m : {&c.stereo->cam0, &c.stereo->cam1}) {
    if (m->width_px != camera.width_px || m->height_px != camera.height_px) {
      throw std::invalid_argument(
          "hardware.camera.width_px: " + options.calibration + " calibrates " +
          (m == &c.stereo->cam0 ? "cam0" : "cam1") + " at " + std::to_string(m->width_px) + "x" +
          std::to_string(m->height_px) + " (resolution), expected the camera's " +
          std::to_string(camera.width_px) + "x" + std::to_string(camera.height_px));
    }
  }
  return c;
}

std::unique_ptr<drivers::MonoCamera> OpenCamera(const runtime::BoardCameraOptions& c,
                                                const std::string& which) {
  const bool triggered = c.trigger.has_value();
  if (c.driver == runtime::CameraDriverKind::kV4l2) {
    drivers::V4l2CameraOptions o;
    o.device = which;
    o.pixel_format = c.pixel_format;
    o.width_px = c.width_px;
    o.height_px = c.height_px;
    // A triggered camera takes its rate from the trigger line.
    if (!triggered) o.frame_rate_hz = c.rate_hz;
    o.buffer_count = c.buffers;
    if (c.exposure_us > 0.0) o.exposure = Duration::FromSeconds(c.exposure_us * 1e-6);
    // Triggered V4L2 sensors expose a vendor "trigger mode" control, where 1
    // is external trigger in the common convention; a camera without one
    // fails start-up instead of free-running unnoticed.
    o.trigger_required = triggered;
    if (triggered) o.trigger_value = 1;
    return std::make_unique<drivers::V4l2Camera>(o);
  }
  drivers::AravisCameraOptions o;
  // An IPv4 address, else a device id (serial numbers are listed as ids too).
  const bool is_address = which.find_first_not_of("0123456789.") == std::string::npos;
  (is_address ? o.address : o.device_id) = which;
  o.pixel_format = c.pixel_format;
  o.width_px = c.width_px;
  o.height_px = c.height_px;
  if (!triggered) o.frame_rate_hz = c.rate_hz;
  if (c.exposure_us > 0.0) o.exposure_us = c.exposure_us;
  o.trigger_enabled = triggered;
  o.buffer_count = c.buffers;
  return std::make_unique<drivers::AravisCamera>(o);
}

}  // namespace

HardwareBoard::HardwareBoard(const runtime::BoardHardwareOptions& options) {
  if (auto problem = options.Problem()) {
    throw std::invalid_argument(problem->first + ": " + problem->second);
  }
  calib::BoardCalibration calibration = LoadCalibration(options);
  // Wheel odometry needs the drives on the bus as well as their calibration.
  if (!options.can) calibration.wheels.reset();
  options_.estimator =
      estimator::FilterOptionsFromCalibration(calibration, options.estimator_config);
  // The IMU runs at the rate the board configures it to.
  options_.estimator.imu.rate_hz = options.imu.rate_hz;
  if (options.camera) {
    CameraSetup head;
    // The filter's body is the IMU frame.
    head.cam0 = calib::CameraInImuFrame(calibration.stereo->cam0, calibration.imu);
    head.cam1 = calib::CameraInImuFrame(calibration.stereo->cam1, calibration.imu);
    head.vo = estimator::VoOptionsFromCalibration(options.camera->rate_hz, options.vo_config);
    options_.camera = head;
  }
  // Cameras stream from the moment they are opened into their few capture
  // buffers (what does not fit counts as lost in the device); the CAN bus
  // and the IMU start only in roverd's StartDevices(), once every thread is
  // ready. Slow openers still go first (GigE discovery, V4L2 negotiation)
  // and the IMU, which must lose nothing, last: a driver that cannot defer
  // its stream then waits the least.
  if (options.camera) OpenCameras(*options.camera);
  if (options.can) OpenCan(*options.can);
  OpenImu(options.imu);
}

void HardwareBoard::OpenCan(const runtime::BoardCanOptions& options) {
  drivers::SocketCanOptions can;
  can.interface = options.interface;
  can.filters = drivers::SocketCanOptions::WheelDriveFilters();
  can_ = std::make_unique<drivers::SocketCanBus>(can);
  description_ += "  can     " + can.interface + " (SocketCAN, wheel-drive filters, " +
                  std::to_string(can_->receive_buffer_bytes() / 1024) + " KiB receive buffer)\n";
}

HardwareBoard::~HardwareBoard() = default;

void HardwareBoard::OpenImu(const runtime::BoardImuOptions& imu) {
  if (imu.driver == runtime::ImuDriverKind::kXsens) {
    drivers::XsensMtiOptions o;
    o.port = imu.device;
    o.baud_rate = imu.baud_rate;
    o.rate_hz = imu.rate_hz;
    o.log = [](const std::string&) {};  // the id goes into the description below
    o.defer_measurement = true;         // streams from roverd's StartDevices()
    auto xsens = std::make_unique<drivers::XsensMtiDriver>(o);
    char id[16];
    std::snprintf(id, sizeof id, "0x%08X", static_cast<unsigned>(xsens->device_id()));
    description_ += "  imu     Xsens MTi " + std::string(id) + " on " + imu.device + " at " +
                    std::to_string(imu.baud_rate) + " baud, " + Hz(imu.rate_hz) + "\n";
    imu_ = std::move(xsens);
    return;
  }
  data_ready_chip_ = std::make_unique<drivers::LibgpiodChip>(imu.data_ready_chip);
  drivers::GpioLineEdgeSourceOptions edges;
  edges.line = static_cast<uint32_t>(imu.data_ready_line);
  edges.consumer = "rover-imu-data-ready";
  edges.edges = drivers::GpioEdges::kRising;
  edges.nominal_period = Duration::FromSeconds(1.0 / imu.rate_hz);
  data_ready_ = std::make_unique<drivers::GpioLineEdgeSource>(*data_ready_chip_, edges);
  drivers::SpidevOptions spi;
  spi.path = imu.device;
  spi_ = std::make_unique<drivers::SpidevDevice>(spi);
  drivers::Adis16448Options o;
  o.rate_hz = imu.rate_hz;
  imu_ = std::make_unique<drivers::Adis16448Driver>(*spi_, *data_ready_, o);
  description_ += "  imu     ADIS16448 on " + imu.device + ", data ready " + imu.data_ready_chip +
                  " line " + std::to_string(imu.data_ready_line) + ", " + Hz(imu.rate_hz) + "\n";
}

void HardwareBoard::OpenCameras(const runtime::BoardCameraOptions& camera) {
  cam0_ = OpenCamera(camera, camera.cam0);
  cam1_ = OpenCamera(camera, camera.cam1);
  drivers::StereoPairerOptions pairing;
  pairing.stamp_tolerance = Duration::FromSeconds(camera.pair_tolerance_s);
  stereo_ = std::make_unique<drivers::StereoPairer>(cam0_.get(), cam1_.get(), pairing);
  const char* kind = camera.driver == runtime::CameraDriverKind::kV4l2 ? "V4L2" : "Aravis";
  // Which V4L2 API each node speaks: worth knowing when a board's capture
  // driver changes.
  auto api = [](const drivers::MonoCamera& c) -> std::string {
    const auto* v4l2 = dynamic_cast<const drivers::V4l2Camera*>(&c);
    return v4l2 != nullptr && v4l2->multi_planar() ? " (multi-planar)" : "";
  };
  description_ += "  camera  " + std::string(kind) + " " + camera.cam0 + api(*cam0_) + " + " +
                  camera.cam1 + api(*cam1_) + ", " + std::to_string(camera.width_px) + "x" +
                  std::to_string(camera.height_px) + " " + camera.pixel_format +
                  ", paired within " +
                  std::to_string(static_cast<int>(camera.pair_tolerance_s * 1e3 + 0.5)) + " ms\n";
  if (camera.trigger) {
    trigger_chip_ = std::make_unique<drivers::LibgpiodChip>(camera.trigger->chip);
    drivers::GpioCameraTriggerOptions t;
    t.rate_hz = camera.rate_hz;
    t.pulse_width = Duration::FromSeconds(camera.trigger->pulse_width_s);
    t.line = static_cast<uint32_t>(camera.trigger->line);
    t.active_low = camera.trigger->active_low;
    trigger_ = std::make_unique<drivers::GpioCameraTrigger>(*trigger_chip_, t);
    description_ += "  trigger " + camera.trigger->chip + " line " +
                    std::to_string(camera.trigger->line) + " at " + Hz(camera.rate_hz) + "\n";
  }
}

std::string HardwareBoard::DeviceReport() const {
  std::string report;
  if (stereo_) {
    const drivers::StereoPairerStats& s = stereo_->stats();
    report += "  stereo  " + std::to_string(s.pairs) + " pairs";
    for (int cam = 0; cam < 2; ++cam) {
      const drivers::StereoPairerCameraStats& c = s.camera[cam];
      report += "; cam" + std::to_string(cam) + " " + std::to_string(c.frames) + " frames (" +
                std::to_string(c.unpaired) + " unpaired, " + std::to_string(c.device_dropped) +
                " lost in the device, " + std::to_string(c.errors) + " errors)";
    }
    report += "; " + std::to_string(s.stamp_mismatches) + " stamp mismatches\n";
  }
  if (can_) {
    const drivers::SocketCanStats s = can_->stats();
    report += "  bus     " + can_->interface() + " " + drivers::ToString(can_->health()) + ": " +
              std::to_string(s.frames) + " frames, " + std::to_string(s.kernel_drops) +
              " kernel drops, " + std::to_string(s.error_frames) + " error frames, " +
              std::to_string(s.bus_off) + " bus-off, " + std::to_string(s.reopens) + " reopens\n";
  }
  return report;
}

RoverdDrivers HardwareBoard::drivers() {
  return {imu_.get(), stereo_.get(), trigger_.get(), can_.get()};
}

}  // namespace rover::roverd
