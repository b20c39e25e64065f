#ifndef ROVER_DRIVERS_CAMERA_CAMERA_TRIGGER_H_
#define ROVER_DRIVERS_CAMERA_CAMERA_TRIGGER_H_

#include "core/time/time.h"
#include "drivers/read_status.h"

namespace rover::drivers {

/// The stereo head's hardware trigger: reports each trigger edge when it is
/// fired, long before its images arrive, so the filter can clone the pose at
/// the capture time without waiting for the exposure and readout (on a board:
/// the GPIO trigger output; in simulation: the GPIO edge model).
class CameraTrigger {
 public:
  virtual ~CameraTrigger() = default;
  /// Waits up to `timeout` for the next trigger edge; its time in *stamp.
  virtual ReadStatus Next(Time* stamp, Duration timeout) = 0;
};

}  // namespace rover::drivers

#endif  // ROVER_DRIVERS_CAMERA_CAMERA_TRIGGER_H_
