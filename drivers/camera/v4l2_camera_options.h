#ifndef ROVER_DRIVERS_CAMERA_V4L2_CAMERA_OPTIONS_H_
#define ROVER_DRIVERS_CAMERA_V4L2_CAMERA_OPTIONS_H_

#include <cstdint>
#include <optional>
#include <string>

#include "core/time/time.h"

namespace rover::drivers {

/// Configuration of one V4l2Camera. Every device setting left unset
/// (std::nullopt) keeps the device's own value. Validate() throws
/// std::invalid_argument "V4l2CameraOptions.<field>: expected ..., found
/// ..." for the first field out of range.
struct V4l2CameraOptions {
  // --- Which device. ---
  /// The video capture node, e.g. "/dev/video0".
  std::string device = "/dev/video0";
  /// Video input to select (VIDIOC_S_INPUT); nullopt keeps the current one.
  std::optional<int> input{};

  // --- Image format (VIDIOC_S_FMT). The device must accept it exactly. ---
  /// V4L2 fourcc as text: "GREY" (delivered as is, zero copy), "Y10",
  /// "Y12", "Y16" (most significant 8 bits), "YUYV" (luma plane) or "MJPG"
  /// (decoded; not real-time safe, see PixelFormatConverter).
  std::string pixel_format = "GREY";
  int width_px = 640;
  int height_px = 480;
  /// Frame rate set through the frame interval (VIDIOC_S_PARM), which the
  /// device must accept within 0.1 %; nullopt keeps the device's rate.
  std::optional<double> frame_rate_hz{};

  // --- Buffering. ---
  /// Capture buffers requested (VIDIOC_REQBUFS, memory-mapped), in [2, 32].
  /// The caller may hold all but one; frames arriving while every buffer is
  /// full or held are lost (sequence gaps, counted as dropped).
  int buffer_count = 4;
  /// Export each buffer as a DMABUF file descriptor (VIDIOC_EXPBUF), for
  /// zero-copy hand-over to other devices; V4l2Camera::dmabuf_fd().
  bool export_dmabuf = false;

  // --- Controls (applied at start-up and after every reconnect). ---
  /// Exposure time through V4L2_CID_EXPOSURE_ABSOLUTE (units of 100 us,
  /// so rounded to 100 us); also switches auto exposure off. Start-up fails
  /// when the device has no such control.
  std::optional<Duration> exposure{};
  /// Raw V4L2_CID_EXPOSURE value in the device's own unit (for sensors
  /// without the absolute control); also switches auto exposure off.
  std::optional<int64_t> exposure_raw{};
  /// Switch auto exposure off (V4L2_CID_EXPOSURE_AUTO = manual) even when
  /// no exposure is set. A device without auto exposure is fine.
  bool auto_exposure_off = true;
  /// V4L2_CID_GAIN in the device's unit; also switches V4L2_CID_AUTOGAIN
  /// off when the device has it. Start-up fails without a gain control.
  std::optional<int64_t> gain{};

  // --- Trigger (a vendor control, looked up by name). ---
  /// Name of the device's trigger-mode control, compared the way v4l2-ctl
  /// prints names (lower case, other characters as '_'): "Trigger Mode"
  /// and "trigger_mode" match the same control.
  std::string trigger_control = "trigger_mode";
  /// Value written to the trigger control; nullopt leaves the trigger
  /// alone. A device without the control is reported (trigger_supported()
  /// false, and in startup_report()) but only fails start-up when
  /// `trigger_required`.
  std::optional<int64_t> trigger_value{};
  bool trigger_required = false;

  // --- Time. ---
  /// Time from the start of exposure to the end of the frame's readout,
  /// subtracted from stamps the device takes at the end of the frame
  /// (V4L2_BUF_FLAG_TSTAMP_SRC_EOF) to get the start of exposure: the
  /// exposure time plus the sensor's readout time (rows x line time).
  /// Stamps taken at the start of exposure (TSTAMP_SRC_SOE) are used as
  /// they are. 0: end-of-frame stamps are delivered uncorrected.
  Duration exposure_and_readout = Duration::Zero();

  // --- Disconnects (ENODEV, POLLERR, a failed stream). ---
  /// Reopen the device from within Next() after it failed.
  bool reconnect = true;
  /// First wait between reopen attempts; doubles up to the maximum.
  Duration reconnect_initial_backoff = Duration::Milliseconds(100);
  Duration reconnect_max_backoff = Duration::Seconds(2);

  /// Throws std::invalid_argument naming the first bad field.
  void Validate() const;
};

}  // namespace rover::drivers

#endif  // ROVER_DRIVERS_CAMERA_V4L2_CAMERA_OPTIONS_H_
