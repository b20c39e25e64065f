#ifndef ROVER_DRIVERS_CAN_SOCKET_CAN_BUS_H_
#define ROVER_DRIVERS_CAN_SOCKET_CAN_BUS_H_

// A Linux SocketCAN interface (can0, vcan0) as a CanBus, through a raw CAN
// socket. This is the minimal version the simulator needs to put its frames
// on a real bus; kernel RX timestamps, filters and error frames come with the
// full driver.

#include <stdexcept>
#include <string>

#include "drivers/can/can_bus.h"

namespace rover::drivers {

class CanError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class SocketCanBus final : public CanBus {
 public:
  /// Opens and binds a raw CAN socket on `interface`. Throws CanError naming
  /// the interface and the system error (no such device, no permission, no
  /// CAN support in the kernel).
  explicit SocketCanBus(const std::string& interface);
  ~SocketCanBus() override;
  SocketCanBus(const SocketCanBus&) = delete;
  SocketCanBus& operator=(const SocketCanBus&) = delete;

  /// Waits up to `timeout` (poll) for a frame; stamps it with the receive
  /// time on CLOCK_MONOTONIC.
  ReadStatus Receive(CanFrame* frame, Duration timeout) override;
  /// Writes one frame; false (and counted) if the kernel refuses it, e.g.
  /// with a full transmit queue.
  bool Send(const CanFrame& frame) override;

  uint64_t send_failures() const { return send_failures_; }
  const std::string& interface() const { return interface_; }

 private:
  std::string interface_;
  int fd_ = -1;
  uint64_t send_failures_ = 0;
};

}  // namespace rover::drivers

#endif  // ROVER_DRIVERS_CAN_SOCKET_CAN_BUS_H_
