#ifndef ROVER_DRIVERS_CAMERA_ARAVIS_CAMERA_H_
#define ROVER_DRIVERS_CAMERA_ARAVIS_CAMERA_H_

// A GigE Vision (or USB3 Vision) camera through Aravis, as a MonoCamera.
//
// Start-up (the constructor) discovers the device, configures it through
// GenICam features, allocates the buffer pool and starts streaming; anything
// wrong there throws AravisCameraError. After that, Next() and Release() are
// the real-time path: no exception, no allocation of ours, no lock of ours,
// never blocking past the caller's timeout. Every problem is counted in
// AravisCameraStats.
//
// A helper thread owned by the camera watches the device's control channel.
// When Aravis reports it lost (the heartbeat failed: cable pulled, camera
// power-cycled), the helper waits until no Next()/Release() is inside the
// stream, tears the stream down and reopens the device with exponential
// backoff; Next() meanwhile waits out its timeout and returns kError.
//
// Aravis and GLib types stay in the .cc, so roverd code never sees GLib.

#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/time/time.h"
#include "drivers/camera/aravis_camera_options.h"
#include "drivers/camera/mono_camera.h"
#include "drivers/read_status.h"

namespace rover::drivers {

/// Start-up failure of an AravisCamera: names the device, what was expected
/// and the underlying Aravis/GLib error.
class AravisCameraError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// One device found by discovery.
struct AravisDeviceInfo {
  std::string device_id{};  ///< what AravisCameraOptions::device_id takes
  std::string serial{};
  std::string address{};  ///< IPv4 for GigE Vision
  std::string vendor{};
  std::string model{};
  std::string protocol{};  ///< "GigEVision", "USB3Vision", "Fake"
};

/// Health counters of one AravisCamera, cumulative since construction
/// (across reconnects).
struct AravisCameraStats {
  uint64_t frames = 0;    ///< delivered by Next() with kOk
  uint64_t timeouts = 0;  ///< Next() calls that returned kTimeout
  uint64_t errors = 0;    ///< Next() calls that returned kError (disconnected)
  /// Buffers handed back incomplete (status != success), by kind. They are
  /// requeued at once and never delivered; their frames count as dropped.
  uint64_t incomplete = 0;
  uint64_t incomplete_missing_packets = 0;  ///< packets missing, resend exhausted/off
  uint64_t incomplete_timeout = 0;          ///< frame_retention expired
  uint64_t incomplete_size_mismatch = 0;    ///< payload or image geometry not as configured
  uint64_t incomplete_aborted = 0;          ///< acquisition stopped mid-frame
  uint64_t incomplete_other = 0;            ///< cleared, wrong packet id, unknown
  /// Sum of CameraFrame::dropped_before: frames the device sent that were
  /// never delivered (incomplete, or lost whole).
  uint64_t dropped_frames = 0;
  /// GigE Vision packet statistics of the stream (arv_gv_stream_get_statistics
  /// and the stream's info counters).
  uint64_t resent_packets = 0;
  uint64_t missing_packets = 0;
  uint64_t resend_requests = 0;
  /// Frames the stream had no free buffer for: the caller held every buffer.
  uint64_t underruns = 0;
  /// Control channel lost (Aravis "control-lost").
  uint64_t disconnects = 0;
  /// Attempts to reopen the device after a disconnect, and successes.
  uint64_t reconnect_attempts = 0;
  uint64_t reconnects = 0;
  /// Frame id jumps that cannot be losses (backwards, or a new device
  /// session): the sequence continues without counting drops.
  uint64_t sequence_resets = 0;
  /// Restarts of the device-clock fit, and late pairs it set aside.
  uint64_t clock_resets = 0;
  uint64_t clock_outliers = 0;
  /// Hand-over time of the last delivered frame: the stream's pop returning
  /// to Next() returning (sequence, clock fit, Mono16 conversion, counters).
  int64_t last_handover_ns = 0;
  /// The device-clock fit after the last frame: host - device offset, drift
  /// of the host against the device, mean excess receive latency.
  int64_t clock_offset_ns = 0;
  double clock_drift_ppm = 0.0;
  int64_t clock_mean_residual_ns = 0;
};

/// A camera through Aravis. Thread model: Next() and Release() on one
/// thread (the camera thread); stats(), connected() and SoftwareTrigger()
/// from any thread.
class AravisCamera final : public MonoCamera {
 public:
  /// Validates `options`, opens the device they select, configures it and
  /// starts streaming. Throws std::invalid_argument for bad options and
  /// AravisCameraError when the device is absent (the message lists the
  /// devices found), refuses a setting (the feature, the value, the GError
  /// message) or the stream cannot be created.
  explicit AravisCamera(const AravisCameraOptions& options);
  /// Stops acquisition, joins the helper thread and frees every buffer.
  /// Frames not yet released become invalid.
  ~AravisCamera() override;
  AravisCamera(const AravisCamera&) = delete;
  AravisCamera& operator=(const AravisCamera&) = delete;

  /// Waits up to `timeout` for the next complete frame. Incomplete buffers
  /// are counted, requeued and skipped within the same call. kOk: *frame
  /// holds the image (valid until Release), its mapped start-of-exposure
  /// time, the 64-bit sequence and the frames lost since the last one.
  /// kTimeout: nothing complete arrived in time. kError: the device is
  /// disconnected (after waiting out `timeout` for a reconnect). Never
  /// throws, never allocates (see the tests for what Aravis/GLib do).
  ReadStatus Next(CameraFrame* frame, Duration timeout) override;
  /// Hands the frame's buffer back to the stream. A frame from before a
  /// reconnect goes back to the new stream. Never blocks or allocates.
  void Release(const CameraFrame& frame) override;

  /// Fires the TriggerSoftware command (trigger_source "Software"). A
  /// control-channel round trip: not for the real-time path. False when
  /// disconnected or the camera refused it.
  bool SoftwareTrigger();

  /// Snapshot of the counters; any thread, lock-free.
  AravisCameraStats stats() const;
  /// False between a disconnect and the reconnect.
  bool connected() const;
  /// The opened device's id (stays the same across reconnects).
  const std::string& device_id() const;
  /// Payload size of one frame in bytes as the camera reports it.
  std::size_t payload_bytes() const;
  /// GVSP packet size in use (configured or negotiated); 0 for USB3 Vision.
  int packet_size_bytes() const;

  /// Runs device discovery on every interface (GigE broadcast, USB) and
  /// lists what answered. Blocks for the discovery time (about 1 s).
  static std::vector<AravisDeviceInfo> ListDevices();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rover::drivers

#endif  // ROVER_DRIVERS_CAMERA_ARAVIS_CAMERA_H_
