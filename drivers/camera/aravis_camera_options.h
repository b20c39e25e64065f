#ifndef ROVER_DRIVERS_CAMERA_ARAVIS_CAMERA_OPTIONS_H_
#define ROVER_DRIVERS_CAMERA_ARAVIS_CAMERA_OPTIONS_H_

#include <optional>
#include <string>

#include "core/time/time.h"
#include "drivers/camera/device_clock_fit.h"

namespace rover::drivers {

/// Configuration of one AravisCamera. Every GenICam setting left unset
/// (std::nullopt / empty) keeps the camera's own value. Validate() throws
/// std::invalid_argument naming the field, what was expected and what was
/// found.
struct AravisCameraOptions {
  // --- Which device. Exactly one of the three must be set. ---
  /// Aravis device id as listed by AravisCamera::ListDevices(), e.g.
  /// "Basler-21234567" or "Aravis-Fake-GV01".
  std::string device_id{};
  /// The device's serial number, e.g. "21234567".
  std::string serial{};
  /// The device's address: IPv4 for GigE Vision ("192.168.10.11").
  std::string address{};

  // --- Image format (GenICam Width, Height, OffsetX/Y, PixelFormat). ---
  int width_px = 640;
  int height_px = 480;
  int offset_x_px = 0;
  int offset_y_px = 0;
  /// "Mono8" (delivered as is) or "Mono16" (converted to 8 bits into a
  /// preallocated image per buffer: value >> mono16_shift_bits).
  std::string pixel_format = "Mono8";
  /// Right shift of a Mono16 pixel to 8 bits: 8 for full-range 16-bit data,
  /// 4 for 12-bit data in 16-bit containers (LSB aligned).
  int mono16_shift_bits = 8;

  // --- Acquisition (AcquisitionFrameRate, ExposureTime, Gain in dB). ---
  /// Free-running frame rate; ignored by the camera while triggered.
  std::optional<double> frame_rate_hz{};
  std::optional<double> exposure_us{};
  /// Analog gain in dB through the SFNC "Gain" feature. A camera that only
  /// has the raw "GainRaw" register is refused when this is set (its unit
  /// is vendor-specific).
  std::optional<double> gain_db{};

  // --- Trigger (TriggerSelector=FrameStart, TriggerMode, TriggerSource). ---
  /// true: one frame per trigger edge on `trigger_source`; false: the camera
  /// free-runs (TriggerMode=Off).
  bool trigger_enabled = false;
  /// "Line1" for the stereo head's GPIO trigger line, "Software" to trigger
  /// through AravisCamera::SoftwareTrigger() (tests).
  std::string trigger_source = "Line1";
  /// TriggerActivation ("RisingEdge", "FallingEdge"); empty keeps the
  /// camera's setting.
  std::string trigger_activation{};

  // --- Buffering. ---
  /// Buffers in the pool, allocated at start-up. A frame held by the caller
  /// keeps its buffer until Release(); with all of them held the camera's
  /// frames are dropped (counted as underruns).
  int buffer_count = 8;

  // --- GigE Vision transport (ignored for USB3 Vision). ---
  /// Ask the camera to resend lost packets (ArvGvStream "packet-resend").
  bool packet_resend = true;
  /// Largest resend request as a fraction of a frame's packets
  /// ("packet-request-ratio"); beyond it the frame is given up.
  double packet_request_ratio = 0.25;
  /// GevSCPSPacketSize in bytes; 0 negotiates the largest the path carries
  /// (arv_camera_gv_auto_packet_size, test packets with the DF bit).
  int packet_size_bytes = 0;
  /// Receive socket buffer (SO_RCVBUF) in bytes, fixed; 0 lets Aravis size
  /// it to one frame. A few frames' worth absorbs scheduling stalls of the
  /// receive thread. The kernel caps it at net.core.rmem_max.
  int socket_buffer_bytes = 8 * 1024 * 1024;
  /// Wait for a missing packet before asking for its resend.
  Duration initial_packet_timeout = Duration::Milliseconds(1);
  /// Wait between resend requests of a still missing packet.
  Duration packet_timeout = Duration::Milliseconds(20);
  /// How long an incomplete frame is kept waiting for its packets before it
  /// is handed over incomplete.
  Duration frame_retention = Duration::Milliseconds(100);

  // --- Time. ---
  /// Subtracted from the fitted receive time to get the start of exposure:
  /// the constant part of "device timestamp -> first packet received"
  /// (exposure, readout start, link), measured once on the bench against
  /// the GPIO trigger edge. 0 gives the earliest possible receive time.
  Duration receive_latency = Duration::Zero();
  /// The device-clock -> CLOCK_MONOTONIC fit.
  DeviceClockFitOptions clock_fit{};

  // --- Disconnects. ---
  /// Reopen the device after the control channel is lost.
  bool reconnect = true;
  /// First wait between reconnect attempts; doubles up to the maximum.
  Duration reconnect_initial_backoff = Duration::Milliseconds(200);
  Duration reconnect_max_backoff = Duration::Seconds(5);

  /// Throws std::invalid_argument naming the first bad field.
  void Validate() const;
};

}  // namespace rover::drivers

#endif  // ROVER_DRIVERS_CAMERA_ARAVIS_CAMERA_OPTIONS_H_
