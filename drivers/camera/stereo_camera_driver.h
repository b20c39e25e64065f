#ifndef ROVER_DRIVERS_CAMERA_STEREO_CAMERA_DRIVER_H_
#define ROVER_DRIVERS_CAMERA_STEREO_CAMERA_DRIVER_H_

#include "core/time/time.h"
#include "drivers/camera/stereo_frame.h"
#include "drivers/read_status.h"

namespace rover::drivers {

/// A triggered stereo pair. Implementations: V4L2 and Aravis pairs, the
/// simulator, dataset replay. A frame's images stay valid until Release().
class StereoCameraDriver {
 public:
  virtual ~StereoCameraDriver() = default;
  /// Waits up to `timeout` for the next paired frame.
  virtual ReadStatus Next(StereoFrame* frame, Duration timeout) = 0;
  /// Returns the frame's buffers to the driver's pool.
  virtual void Release(const StereoFrame& frame) = 0;
};

}  // namespace rover::drivers

#endif  // ROVER_DRIVERS_CAMERA_STEREO_CAMERA_DRIVER_H_
