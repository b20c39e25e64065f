#ifndef ROVER_DRIVERS_CAMERA_V4L2_CAMERA_H_
#define ROVER_DRIVERS_CAMERA_V4L2_CAMERA_H_

// A Video4Linux2 capture device (a MIPI CSI-2 sensor behind the board's
// capture interface, a UVC camera; vivid on the HIL bench) as a MonoCamera.
//
// Start-up (the constructor) opens the node, checks it is a capture device
// that streams (through the single-planar API, or the multi-planar one when
// that is all the driver offers, as many SoC CSI-2 receivers do; formats
// must then still be in one memory plane), negotiates the exact format, size and frame
// interval, applies the controls, maps `buffer_count` buffers, queues them
// and starts streaming. Anything wrong there throws V4l2CameraError naming
// the device, what was asked, what the device has, and the system error.
//
// After that, Next() and Release() are the real-time path: no exception, no
// allocation (except decoding MJPG, see PixelFormatConverter), no lock,
// never blocking past the caller's timeout (a reopen attempt may overrun it
// by the time its ioctls take). Every problem is counted in
// V4l2CameraStats.
//
// Frames. Next() dequeues a filled buffer (VIDIOC_DQBUF), converts it to the
// 8-bit mono view (GREY zero copy, the rest into a preallocated image per
// buffer) and hands it over until Release() requeues it (VIDIOC_QBUF).
// Buffers the driver flags with V4L2_BUF_FLAG_ERROR, and buffers shorter
// than a frame (or MJPG that does not decode), are counted, requeued at once
// and never delivered; their frames count as dropped.
//
// Sequence. The driver's 32-bit sequence is extended to 64 bits; a gap of n
// means n - 1 frames lost (every buffer was full or held, or an error
// buffer): CameraFrame::dropped_before and stats.dropped_frames. A sequence
// that does not advance (backwards or repeated) is counted as a reset, not
// as losses. After a reconnect the new stream continues at the next number;
// frames lost during the outage are not known and not counted as dropped.
//
// Time. CameraFrame::stamp is the start of exposure on CLOCK_MONOTONIC:
//  - the buffer flags must say V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC; any other
//    clock (COPY, UNKNOWN) is counted (foreign_clock_stamps) and replaced by
//    the dequeue time, which is then treated as an end-of-frame stamp;
//  - a start-of-exposure stamp (V4L2_BUF_FLAG_TSTAMP_SRC_SOE) is used as is;
//  - an end-of-frame stamp (V4L2_BUF_FLAG_TSTAMP_SRC_EOF, the V4L2 default:
//    taken when the last line arrived) is moved back by
//    options.exposure_and_readout, the time from the start of exposure to
//    the end of readout, which only the integrator knows (exposure +
//    rows x line time for a rolling-shutter sensor).
// A stamp not later than the previous frame's is delivered and counted
// (backward_stamps).
//
// Disconnects. ENODEV from an ioctl, POLLERR/POLLHUP without a buffer, or a
// failed stream (EIO) mark the camera disconnected: the stream is stopped,
// the device closed and every buffer the caller does not hold unmapped (a
// held frame's memory stays mapped until its Release()). Next() then
// reopens and reconfigures the device with exponential backoff, within its
// timeout, once every old frame is released, and returns kError while the
// device stays away. The reopen path allocates nothing either.
//
// Thread model: Next(), Release(), dmabuf_fd() and the control functions on
// one thread (the camera thread); stats() and health() from any thread.

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/time/time.h"
#include "drivers/camera/mono_camera.h"
#include "drivers/camera/pixel_format_converter.h"
#include "drivers/camera/v4l2_camera_options.h"
#include "drivers/read_status.h"

namespace rover::drivers {

/// Start-up failure of a V4l2Camera, or a refused control: the message names
/// the device, what was expected, what was found and the system error.
class V4l2CameraError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

enum class V4l2CameraHealth : uint8_t {
  kStreaming,     ///< the device streams (or waits for its next frame)
  kDisconnected,  ///< the device failed or disappeared; being reopened
};

/// "streaming", "disconnected".
const char* ToString(V4l2CameraHealth health);

/// Health counters of one V4l2Camera, cumulative since construction (across
/// reconnects).
struct V4l2CameraStats {
  uint64_t frames = 0;    ///< delivered by Next() with kOk
  uint64_t timeouts = 0;  ///< Next() calls that returned kTimeout
  uint64_t errors = 0;    ///< Next() calls that returned kError (disconnected)
  /// Sum of CameraFrame::dropped_before: frames the device counted but never
  /// delivered (no free buffer, error buffers, short or undecodable ones).
  uint64_t dropped_frames = 0;
  uint64_t error_buffers = 0;    ///< flagged V4L2_BUF_FLAG_ERROR, requeued
  uint64_t short_buffers = 0;    ///< bytesused below one frame, requeued
  uint64_t decode_errors = 0;    ///< MJPG that did not decode to the negotiated size
  uint64_t sequence_resets = 0;  ///< sequence repeated or went backwards
  /// Buffers whose stamp is not on CLOCK_MONOTONIC (their dequeue time is
  /// used instead).
  uint64_t foreign_clock_stamps = 0;
  /// Stamps not later than the previous frame's.
  uint64_t backward_stamps = 0;
  /// End-of-frame stamps moved back by exposure_and_readout.
  uint64_t end_of_frame_stamps = 0;
  uint64_t disconnects = 0;         ///< times the device failed or vanished
  uint64_t reconnect_attempts = 0;  ///< reopen attempts after a disconnect
  uint64_t reconnects = 0;          ///< successful reopens
  uint64_t bad_releases = 0;        ///< Release() of a frame not held (ignored)
  int last_errno = 0;               ///< errno of the last failure, 0 if none
  /// Time from the return of VIDIOC_DQBUF to the return of Next() for the
  /// last frame and the largest so far (conversion included).
  int64_t last_handover_ns = 0;
  int64_t max_handover_ns = 0;
};

/// One control of the device, as VIDIOC_QUERY_EXT_CTRL reports it.
struct V4l2ControlInfo {
  uint32_t id = 0;
  std::string name{};  ///< normalised like v4l2-ctl: "gain", "trigger_mode"
  uint32_t type = 0;   ///< V4L2_CTRL_TYPE_*
  int64_t minimum = 0;
  int64_t maximum = 0;
  uint64_t step = 0;
  int64_t default_value = 0;
  uint32_t flags = 0;  ///< V4L2_CTRL_FLAG_*
};

/// A camera through V4L2. See the file comment.
class V4l2Camera final : public MonoCamera {
 public:
  /// Validates `options`, opens the device, negotiates the format, applies
  /// the controls and starts streaming. Throws std::invalid_argument for bad
  /// options and V4l2CameraError when the device is missing or not a
  /// streaming capture device, cannot deliver the exact format, size or
  /// frame interval (the message lists what it offers), refuses a control,
  /// or cannot map or start its buffers.
  explicit V4l2Camera(const V4l2CameraOptions& options);
  /// Stops streaming, unmaps every buffer and closes the device. Frames not
  /// yet released become invalid.
  ~V4l2Camera() override;
  V4l2Camera(const V4l2Camera&) = delete;
  V4l2Camera& operator=(const V4l2Camera&) = delete;

  /// Waits up to `timeout` for the next good frame. Error and short
  /// buffers met on the way are counted, requeued and skipped within the
  /// same call. kOk: *frame holds the image (valid until Release), its start
  /// of exposure, the 64-bit sequence and the frames lost since the last
  /// one. kTimeout: no frame in time (also when the caller holds every
  /// buffer). kError: the device is disconnected and did not come back
  /// within `timeout`. Never throws; never allocates (MJPG excepted).
  ReadStatus Next(CameraFrame* frame, Duration timeout) override;
  /// Requeues the frame's buffer (after a disconnect: unmaps it). A frame
  /// not held, released twice, or from an older stream is counted in
  /// bad_releases and ignored. Never blocks or allocates.
  void Release(const CameraFrame& frame) override;

  /// Snapshot of the counters; any thread, lock-free.
  V4l2CameraStats stats() const;
  /// Any thread, lock-free.
  V4l2CameraHealth health() const { return health_.load(std::memory_order_relaxed); }

  const std::string& device() const { return options_.device; }
  /// The negotiated format (exactly the requested one).
  uint32_t fourcc() const { return fourcc_; }
  int width_px() const { return options_.width_px; }
  int height_px() const { return options_.height_px; }
  /// Row pitch of the capture buffers (the GREY view's stride).
  std::size_t bytes_per_line() const { return bytes_per_line_; }
  /// Buffers the driver allocated (it may grant more than requested).
  int buffer_count() const { return buffer_count_; }
  /// The device's frame rate after negotiation (VIDIOC_G_PARM), 0 if the
  /// device does not report a frame interval.
  double frame_rate_hz() const { return frame_rate_hz_; }
  /// False when the trigger control was asked for and the device has none.
  bool trigger_supported() const { return trigger_supported_; }
  /// Start-up notes on what the device does not support (no auto exposure
  /// control, no trigger control, ...), one line each, for the log.
  const std::vector<std::string>& startup_report() const { return startup_report_; }
  /// The DMABUF file descriptor of capture buffer `buffer_index` (a
  /// CameraFrame's buffer_index) while streaming, with export_dmabuf; -1
  /// otherwise. Owned by the camera; invalid after a reconnect.
  int dmabuf_fd(int buffer_index) const;

  // --- Controls by name (not real-time: one or more ioctls each). Names
  // are compared normalised ("Trigger Mode" == "trigger_mode"). ---

  /// Every control of the device (disabled ones excluded). Throws
  /// V4l2CameraError while disconnected.
  std::vector<V4l2ControlInfo> ListControls() const;
  /// The control's current value; nullopt when the device has no such
  /// control, it is write-only, or the device is disconnected.
  std::optional<int64_t> GetControl(const std::string& name) const;
  /// Writes a control (integer, boolean, menu, button, 64-bit types) and
  /// returns the value read back (the written one for write-only
  /// controls). Throws V4l2CameraError naming the device, the control and
  /// the value when there is no such control, the value is outside its
  /// range, or the device refuses it (with strerror).
  int64_t SetControl(const std::string& name, int64_t value);

  /// Lowercase, every run of other characters than [a-z0-9] as one '_',
  /// none at either end: "Trigger Mode" -> "trigger_mode".
  static std::string NormalizeControlName(const std::string& name);

  /// True when the device streams through the multi-planar API
  /// (V4L2_BUF_TYPE_VIDEO_CAPTURE_MPLANE).
  bool multi_planar() const { return multi_planar_; }

  /// Most capture buffers a camera maps (VIDEO_MAX_FRAME).
  static constexpr int kMaxBuffers = 32;

 private:
  /// What went wrong while (re)starting; plain data so the reopen path can
  /// fill it without allocating.
  struct StartFailure;
  struct Buffer {
    void* start = nullptr;
    std::size_t length = 0;
    bool mapped = false;
    bool held = false;        ///< handed out by Next(), not yet released
    uint32_t generation = 0;  ///< stream generation it was handed out in
    int dmabuf_fd = -1;
  };

  /// Opens and configures the device and starts streaming; false with
  /// *failure filled in (the device may be left half open: call
  /// StopAndClose()).
  bool OpenAndStart(StartFailure* failure);
  bool Negotiate(StartFailure* failure);
  bool ApplyControls(StartFailure* failure);
  bool StartBuffers(StartFailure* failure);
  /// Stops streaming, unmaps the buffers the caller does not hold and
  /// closes the device.
  void StopAndClose();
  /// Turns a start-up failure into the exception's message (lists formats,
  /// sizes, intervals and controls the device offers).
  std::string Describe(const StartFailure& failure) const;
  void MarkDisconnected(int error);
  /// Sleeps until the next reopen attempt or `deadline`, whichever is
  /// first, then tries; true once streaming again.
  bool WaitAndReconnect(Time deadline);

  enum class Dequeued { kFrame, kSkipped, kEmpty, kFailed };
  Dequeued DequeueOne(CameraFrame* frame, bool poll_error);
  /// Requeues buffer `index`; false (and disconnected) when the device
  /// refuses.
  bool Queue(uint32_t index);

  V4l2CameraOptions options_;
  uint32_t fourcc_ = 0;
  bool multi_planar_ = false;  ///< chosen from the capabilities at open
  std::size_t bytes_per_line_ = 0;
  std::size_t size_image_ = 0;
  int buffer_count_ = 0;
  double frame_rate_hz_ = 0.0;
  bool trigger_supported_ = true;
  bool has_auto_exposure_control_ = false;
  std::string trigger_control_normalized_{};
  std::vector<std::string> startup_report_{};
  std::unique_ptr<PixelFormatConverter> converter_{};

  int fd_ = -1;
  std::array<Buffer, kMaxBuffers> buffers_{};
  int held_count_ = 0;
  uint32_t generation_ = 0;
  // Sequence and stamp tracking across frames and reconnects.
  bool have_sequence_ = false;   ///< a frame was delivered in this stream
  bool have_any_frame_ = false;  ///< a frame was ever delivered
  uint32_t last_raw_sequence_ = 0;
  uint64_t last_sequence_ = 0;
  Time last_stamp_{};
  // Reconnect backoff.
  Time next_reconnect_{};
  Duration backoff_{};

  std::atomic<V4l2CameraHealth> health_{V4l2CameraHealth::kStreaming};
  std::atomic<uint64_t> frames_{0}, timeouts_{0}, errors_{0}, dropped_frames_{0}, error_buffers_{0},
      short_buffers_{0}, decode_errors_{0}, sequence_resets_{0}, foreign_clock_stamps_{0},
      backward_stamps_{0}, end_of_frame_stamps_{0}, disconnects_{0}, reconnect_attempts_{0},
      reconnects_{0}, bad_releases_{0};
  std::atomic<int> last_errno_{0};
  std::atomic<int64_t> last_handover_ns_{0}, max_handover_ns_{0};
};

}  // namespace rover::drivers

#endif  // ROVER_DRIVERS_CAMERA_V4L2_CAMERA_H_
