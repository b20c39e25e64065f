#ifndef ROVER_DRIVERS_CAN_CAN_BUS_H_
#define ROVER_DRIVERS_CAN_CAN_BUS_H_

#include "core/time/time.h"
#include "drivers/can/can_frame.h"
#include "drivers/read_status.h"

namespace rover::drivers {

/// A CAN interface: SocketCAN (can0, vcan0), an in-process bus, or replay.
class CanBus {
 public:
  virtual ~CanBus() = default;
  /// Starts delivering frames, once, just before the reader's loop (start-up:
  /// may block). Frames that arrived before are not delivered: the drives
  /// send whether or not anyone listens, and a backlog from the process's
  /// start-up would overflow the receive queue and be stale anyway.
  /// Default: nothing to do.
  virtual void Start() {}
  /// Waits up to `timeout` for the next frame.
  virtual ReadStatus Receive(CanFrame* frame, Duration timeout) = 0;
  /// Queues a frame for sending; false if the bus refused it.
  virtual bool Send(const CanFrame& frame) = 0;
};

}  // namespace rover::drivers

#endif  // ROVER_DRIVERS_CAN_CAN_BUS_H_
