#include "firmware/runtime/board/board_hardware_options.h"

namespace rover::runtime {
namespace {

using Issue = std::optional<std::pair<std::string, std::string>>;

Issue Expect(bool ok, const std::string& key, const std::string& expected,
             const std::string& found) {
  if (ok) return std::nullopt;
  return std::make_pair("hardware." + key, "expected " + expected + ", found " + found);
}

std::string Quoted(const std::string& s) { return "\"" + s + "\""; }

}  // namespace

BoardHardwareOptions BoardHardwareOptions::Load(const ConfigNode& node) {
  BoardHardwareOptions o;
  o.calibration = node.Get<std::string>("calibration");
  o.estimator_config = node.Get<std::string>("estimator_config", "");
  o.vo_config = node.Get<std::string>("vo_config", "");

  const ConfigNode imu = node.Child("imu");
  o.imu.driver = imu.GetEnum<ImuDriverKind>(
      "driver", {{"xsens", ImuDriverKind::kXsens}, {"adis16448", ImuDriverKind::kAdis16448}});
  o.imu.device = imu.Get<std::string>("device");
  o.imu.rate_hz = imu.Get<double>("rate_hz", o.imu.rate_hz);
  o.imu.baud_rate = imu.Get<int>("baud_rate", o.imu.baud_rate);
  o.imu.data_ready_chip = imu.Get<std::string>("data_ready_chip", o.imu.data_ready_chip);
  o.imu.data_ready_line = imu.Get<int>("data_ready_line", o.imu.data_ready_line);

  if (node.Has("camera")) {
    const ConfigNode cam = node.Child("camera");
    BoardCameraOptions c;
    c.driver = cam.GetEnum<CameraDriverKind>(
        "driver", {{"v4l2", CameraDriverKind::kV4l2}, {"aravis", CameraDriverKind::kAravis}});
    c.cam0 = cam.Get<std::string>("cam0");
    c.cam1 = cam.Get<std::string>("cam1");
    c.width_px = cam.Get<int>("width_px", c.width_px);
    c.height_px = cam.Get<int>("height_px", c.height_px);
    c.pixel_format = cam.Get<std::string>(
        "pixel_format", c.driver == CameraDriverKind::kAravis ? "Mono8" : c.pixel_format);
    c.rate_hz = cam.Get<double>("rate_hz", c.rate_hz);
    c.exposure_us = cam.Get<double>("exposure_us", c.exposure_us);
    c.buffers = cam.Get<int>("buffers", c.buffers);
    c.pair_tolerance_s = cam.Get<double>("pair_tolerance_s", c.pair_tolerance_s);
    if (cam.Has("trigger")) {
      const ConfigNode t = cam.Child("trigger");
      BoardTriggerOptions trigger;
      trigger.chip = t.Get<std::string>("chip", trigger.chip);
      trigger.line = t.Get<int>("line", trigger.line);
      trigger.pulse_width_s = t.Get<double>("pulse_width_s", trigger.pulse_width_s);
      trigger.active_low = t.Get<bool>("active_low", trigger.active_low);
      c.trigger = trigger;
    }
    o.camera = c;
  }
  if (node.Has("can")) {
    BoardCanOptions can;
    can.interface = node.Child("can").Get<std::string>("interface", can.interface);
    o.can = can;
  }
  if (Issue p = o.Problem()) {
    // Report at the key inside the section ("hardware." is the section).
    node.Fail(p->first.substr(std::string("hardware.").size()), p->second);
  }
  return o;
}

std::optional<std::pair<std::string, std::string>> BoardHardwareOptions::Problem() const {
  if (Issue p = Expect(!calibration.empty(), "calibration",
                       "the folder holding imu0/sensor.yaml (and cam0/, cam1/)", "an empty path")) {
    return p;
  }
  if (Issue p = Expect(!imu.device.empty(), "imu.device", "a device path", "an empty path"))
    return p;
  if (imu.driver == ImuDriverKind::kXsens) {
    if (Issue p = Expect(imu.rate_hz >= 1.0 && imu.rate_hz <= 2000.0, "imu.rate_hz",
                         "a rate in [1, 2000] Hz", std::to_string(imu.rate_hz))) {
      return p;
    }
    if (Issue p = Expect(imu.baud_rate > 0, "imu.baud_rate", "a positive baud rate",
                         std::to_string(imu.baud_rate))) {
      return p;
    }
  } else {
    if (Issue p =
            Expect(imu.rate_hz > 0.0 && imu.rate_hz <= 819.2, "imu.rate_hz",
                   "a rate in (0, 819.2] Hz (819.2 SPS decimated)", std::to_string(imu.rate_hz))) {
      return p;
    }
    if (Issue p = Expect(imu.data_ready_line >= 0, "imu.data_ready_line", "a line offset >= 0",
                         std::to_string(imu.data_ready_line))) {
      return p;
    }
  }
  if (camera) {
    const BoardCameraOptions& c = *camera;
    if (Issue p = Expect(!c.cam0.empty() && !c.cam1.empty() && c.cam0 != c.cam1, "camera.cam0",
                         "two different cameras", Quoted(c.cam0) + " and " + Quoted(c.cam1))) {
      return p;
    }
    if (Issue p =
            Expect(c.width_px > 0 && c.height_px > 0 && c.width_px <= 8192 && c.height_px <= 8192,
                   "camera.width_px", "an image size within 8192 x 8192",
                   std::to_string(c.width_px) + " x " + std::to_string(c.height_px))) {
      return p;
    }
    if (Issue p = Expect(c.rate_hz >= 1.0 && c.rate_hz <= 100.0, "camera.rate_hz",
                         "a rate in [1, 100] Hz", std::to_string(c.rate_hz))) {
      return p;
    }
    if (Issue p = Expect(c.exposure_us >= 0.0 && c.exposure_us < 1e6 / c.rate_hz,
                         "camera.exposure_us", "0 (the camera's own) or less than a frame period",
                         std::to_string(c.exposure_us))) {
      return p;
    }
    if (Issue p = Expect(c.buffers >= 2 && c.buffers <= 32, "camera.buffers", "2 to 32 buffers",
                         std::to_string(c.buffers))) {
      return p;
    }
    if (Issue p = Expect(c.pair_tolerance_s > 0.0 && c.pair_tolerance_s < 0.5 / c.rate_hz,
                         "camera.pair_tolerance_s", "more than 0 and less than half a frame period",
                         std::to_string(c.pair_tolerance_s))) {
      return p;
    }
    if (c.trigger) {
      if (Issue p = Expect(c.trigger->line >= 0, "camera.trigger.line", "a line offset >= 0",
                           std::to_string(c.trigger->line))) {
        return p;
      }
      if (Issue p =
              Expect(c.trigger->pulse_width_s > 0.0 && c.trigger->pulse_width_s < 1.0 / c.rate_hz,
                     "camera.trigger.pulse_width_s", "more than 0 and less than a period",
                     std::to_string(c.trigger->pulse_width_s))) {
        return p;
      }
    }
  }
  if (can) {
    if (Issue p = Expect(!can->interface.empty() && can->interface.size() < 16, "can.interface",
                         "an interface name of 1 to 15 characters", Quoted(can->interface))) {
      return p;
    }
  }
  return std::nullopt;
}

}  // namespace rover::runtime
