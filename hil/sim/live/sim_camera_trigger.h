#ifndef ROVER_HIL_SIM_LIVE_SIM_CAMERA_TRIGGER_H_
#define ROVER_HIL_SIM_LIVE_SIM_CAMERA_TRIGGER_H_

// The simulated trigger line behind the firmware's CameraTrigger interface:
// the GPIO edge model's camera trigger times, each handed out when due (real
// time) or at once (lockstep). The stereo driver renders at the same times.

#include <cstddef>
#include <vector>

#include "drivers/camera/camera_trigger.h"
#include "drivers/replay/euroc_replay.h"
#include "hil/sim/sensors/gpio_edge_model.h"

namespace rover::sim {

class SimCameraTrigger final : public drivers::CameraTrigger {
 public:
  /// `clock` must outlive the trigger.
  SimCameraTrigger(const GpioEdgeModel& model, const drivers::ReplayClock& clock, Time start,
                   Time end)
      : times_(model.CameraTriggerTimes(start, end)), clock_(clock) {}
  drivers::ReadStatus Next(Time* stamp, Duration timeout) override {
    if (next_ >= times_.size()) return drivers::ReadStatus::kEndOfStream;
    if (!clock_.WaitUntilDue(times_[next_], timeout)) return drivers::ReadStatus::kTimeout;
    *stamp = times_[next_++];
    return drivers::ReadStatus::kOk;
  }

 private:
  std::vector<Time> times_;
  const drivers::ReplayClock& clock_;
  std::size_t next_ = 0;
};

}  // namespace rover::sim

#endif  // ROVER_HIL_SIM_LIVE_SIM_CAMERA_TRIGGER_H_
