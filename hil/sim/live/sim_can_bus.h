#ifndef ROVER_HIL_SIM_LIVE_SIM_CAN_BUS_H_
#define ROVER_HIL_SIM_LIVE_SIM_CAN_BUS_H_

// The four simulated wheel drives on a CAN bus, behind the firmware's CanBus
// interface: SYNC, TPDO1 and heartbeat frames as the CANopen drives send
// them (DESIGN.md), each delivered when its time comes.

#include <deque>

#include "drivers/can/can_bus.h"
#include "drivers/replay/euroc_replay.h"
#include "hil/sim/sensors/wheel_odometry_model.h"

namespace rover::sim {

class SimWheelCanBus final : public drivers::CanBus {
 public:
  /// `trajectory`, `terrain` and `clock` must outlive the bus.
  SimWheelCanBus(const WheelOdometryModelOptions& options, const RoverTrajectory& trajectory,
                 const Heightfield& terrain, const drivers::ReplayClock& clock, Time start,
                 Time end);
  drivers::ReadStatus Receive(drivers::CanFrame* frame, Duration timeout) override;
  /// The simulated drives ignore commands; frames sent are counted.
  bool Send(const drivers::CanFrame& frame) override;
  uint64_t frames_sent() const { return frames_sent_; }

 private:
  WheelOdometryModel model_;
  const drivers::ReplayClock& clock_;
  Time generated_until_;
  Time end_;
  std::vector<drivers::CanFrame> batch_;
  std::size_t next_in_batch_ = 0;
  uint64_t frames_sent_ = 0;
};

}  // namespace rover::sim

#endif  // ROVER_HIL_SIM_LIVE_SIM_CAN_BUS_H_
