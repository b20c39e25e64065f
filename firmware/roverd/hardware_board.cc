#include "firmware/roverd/hardware_board.h"

#include <cstdio>
#include <filesystem>
#include <stdexcept>

#include "drivers/camera/aravis_camera.h"
#include "drivers/camera/stereo_pairer.h"
#include "drivers/camera/v4l2_camera.h"
#include "drivers/gpio/gpio_camera_trigger.h"
#include "drivers/gpio/gpio_line_edge_source.h"
#include "drivers/gpio/libgpiod_chip.h"
#include "drivers/imu/adis16448_driver.h"
#include "drivers/imu/spidev_device.h"
#include "drivers/imu/xsens_mti_driver.h"
#include "drivers/replay/euroc_dataset.h"
#include "firmware/roverd/sensor_calibration.h"

namespace rover::roverd {
namespace {

namespace fs = std::filesystem;

// "400 Hz", "409.6 Hz": rates as a user wrote them.
std::string Hz(double rate_hz) {
  char text[32];
  std::snprintf(text, sizeof text, "%g Hz", rate_hz);
  return text;
}

std::string SensorYaml(const std::string& folder, const std::string& sensor) {
  const fs::path path = fs::path(folder) / sensor / "sensor.yaml";
  if (!fs::is_regular_file(path)) {
    throw std::invalid_argument("hardware.calibration: expected " + path.string() +
                                " (EuRoC sensor.yaml of " + sensor + "), found no such file");
  }
  return path.string();
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
  const drivers::ImuCalibration imu =
      drivers::LoadImuCalibration(SensorYaml(options.calibration, "imu0"));
  options_.estimator = FilterOptionsFromCalibration(imu, options.estimator_config);
  options_.estimator.imu.rate_hz = options.imu.rate_hz;
  if (options.camera) {
    const Eigen::Isometry3d T_imu_body = imu.T_body_imu.inverse();
    CameraSetup head;
    head.cam0 = ToCameraModel(
        drivers::LoadCameraCalibration(SensorYaml(options.calibration, "cam0")), T_imu_body);
    head.cam1 = ToCameraModel(
        drivers::LoadCameraCalibration(SensorYaml(options.calibration, "cam1")), T_imu_body);
    if (!options.vo_config.empty()) {
      head.vo = estimator::vo::StereoOdometryOptions::LoadFile(options.vo_config);
    }
    head.vo.checks.nominal_rate_hz = options.camera->rate_hz;
    options_.camera = head;
  }
  OpenImu(options.imu);
  if (options.camera) OpenCameras(*options.camera);
  if (options.can) {
    drivers::SocketCanOptions can;
    can.interface = options.can->interface;
    can.filters = drivers::SocketCanOptions::WheelDriveFilters();
    can_ = std::make_unique<drivers::SocketCanBus>(can);
    description_ += "  can     " + can.interface + " (SocketCAN, wheel-drive filters, " +
                    std::to_string(can_->receive_buffer_bytes() / 1024) + " KiB receive buffer)\n";
  }
}

HardwareBoard::~HardwareBoard() = default;

void HardwareBoard::OpenImu(const runtime::BoardImuOptions& imu) {
  if (imu.driver == runtime::ImuDriverKind::kXsens) {
    drivers::XsensMtiOptions o;
    o.port = imu.device;
    o.baud_rate = imu.baud_rate;
    o.rate_hz = imu.rate_hz;
    o.log = [](const std::string&) {};  // the id goes into the description below
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
  description_ += "  camera  " + std::string(kind) + " " + camera.cam0 + " + " + camera.cam1 +
                  ", " + std::to_string(camera.width_px) + "x" + std::to_string(camera.height_px) +
                  " " + camera.pixel_format + "\n";
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

RoverdDrivers HardwareBoard::drivers() {
  return {imu_.get(), stereo_.get(), trigger_.get(), can_.get()};
}

}  // namespace rover::roverd
