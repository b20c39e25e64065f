#include "drivers/camera/v4l2_camera_options.h"

#include <cctype>
#include <cmath>
#include <stdexcept>

#include "drivers/camera/pixel_format_converter.h"

namespace rover::drivers {
namespace {

[[noreturn]] void Fail(const std::string& field, const std::string& expected,
                       const std::string& found) {
  throw std::invalid_argument("V4l2CameraOptions." + field + ": expected " + expected + ", found " +
                              found);
}

}  // namespace

void V4l2CameraOptions::Validate() const {
  if (device.empty()) Fail("device", "a device node path such as /dev/video0", "''");
  if (input.has_value() && *input < 0) Fail("input", ">= 0", std::to_string(*input));
  uint32_t fourcc = 0;
  try {
    fourcc = FourccFromString(pixel_format);
  } catch (const std::invalid_argument&) {
    Fail("pixel_format", "GREY, Y10, Y12, Y16, YUYV or MJPG", "'" + pixel_format + "'");
  }
  if (!PixelFormatConverter::Supports(fourcc)) {
    Fail("pixel_format", "GREY, Y10, Y12, Y16, YUYV or MJPG", "'" + pixel_format + "'");
  }
  if (width_px < 1 || width_px > 16384) Fail("width_px", "1 to 16384", std::to_string(width_px));
  if (height_px < 1 || height_px > 16384)
    Fail("height_px", "1 to 16384", std::to_string(height_px));
  if (frame_rate_hz.has_value() &&
      (!std::isfinite(*frame_rate_hz) || *frame_rate_hz <= 0.0 || *frame_rate_hz > 10000.0)) {
    Fail("frame_rate_hz", "a rate in (0, 10000] Hz", std::to_string(*frame_rate_hz));
  }
  if (buffer_count < 2 || buffer_count > 32)
    Fail("buffer_count", "2 to 32", std::to_string(buffer_count));
  if (exposure.has_value() &&
      (*exposure < Duration::Microseconds(100) || *exposure > Duration::Seconds(10))) {
    Fail("exposure", "100 us to 10 s (V4L2_CID_EXPOSURE_ABSOLUTE counts 100 us)",
         exposure->ToString());
  }
  if (exposure.has_value() && exposure_raw.has_value()) {
    Fail("exposure_raw", "unset when exposure is set (one exposure control at a time)",
         std::to_string(*exposure_raw));
  }
  if (exposure_raw.has_value() && *exposure_raw < 0) {
    Fail("exposure_raw", ">= 0", std::to_string(*exposure_raw));
  }
  if (trigger_value.has_value() || trigger_required) {
    bool has_alnum = false;
    for (const char c : trigger_control)
      has_alnum = has_alnum || std::isalnum(static_cast<unsigned char>(c)) != 0;
    if (!has_alnum)
      Fail("trigger_control", "a control name such as 'trigger_mode'", "'" + trigger_control + "'");
  }
  if (trigger_required && !trigger_value.has_value()) {
    Fail("trigger_value", "a value when trigger_required is set", "none");
  }
  if (exposure_and_readout < Duration::Zero() || exposure_and_readout > Duration::Seconds(10)) {
    Fail("exposure_and_readout", "0 to 10 s", exposure_and_readout.ToString());
  }
  if (reconnect_initial_backoff <= Duration::Zero()) {
    Fail("reconnect_initial_backoff", "> 0", reconnect_initial_backoff.ToString());
  }
  if (reconnect_max_backoff < reconnect_initial_backoff) {
    Fail("reconnect_max_backoff",
         ">= reconnect_initial_backoff (" + reconnect_initial_backoff.ToString() + ")",
         reconnect_max_backoff.ToString());
  }
}

}  // namespace rover::drivers
