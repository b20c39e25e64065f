#ifndef ROVER_DRIVERS_CAMERA_MONO_CAMERA_H_
#define ROVER_DRIVERS_CAMERA_MONO_CAMERA_H_

#include <cstdint>

#include "core/time/time.h"
#include "drivers/camera/stereo_frame.h"
#include "drivers/read_status.h"

namespace rover::drivers {

/// One image of one camera, held in the driver's buffer pool until
/// MonoCamera::Release().
struct CameraFrame {
  /// Start of exposure on CLOCK_MONOTONIC (V4L2: the buffer timestamp when
  /// its flags say monotonic + start-of-exposure, else corrected; Aravis: the
  /// device timestamp through the tick -> host fit).
  Time stamp;
  /// The device's frame counter (V4L2 sequence, GigE Vision frame id),
  /// extended to 64 bits; a gap means frames were lost before this one.
  uint64_t sequence = 0;
  /// Frames lost between the previous delivered frame and this one.
  uint32_t dropped_before = 0;
  /// 8-bit mono view (other pixel formats are converted by the driver).
  ImageView image;
  /// Which pool buffer holds the image; Release() hands it back.
  int buffer_index = -1;
};

/// A single streaming camera: V4L2, Aravis (GigE Vision / USB3 Vision), or a
/// test double. Two of them make a stereo head through StereoPairer. Next()
/// runs on the camera thread: after start-up it does not allocate, take
/// locks or block longer than `timeout`.
class MonoCamera {
 public:
  virtual ~MonoCamera() = default;
  /// Waits up to `timeout` for the next frame.
  virtual ReadStatus Next(CameraFrame* frame, Duration timeout) = 0;
  /// Returns the frame's buffer to the driver (requeues it).
  virtual void Release(const CameraFrame& frame) = 0;
};

}  // namespace rover::drivers

#endif  // ROVER_DRIVERS_CAMERA_MONO_CAMERA_H_
