#include "hil/sim/live/sim_imu_driver.h"

namespace rover::sim {

SimImuDriver::SimImuDriver(const ImuModelOptions& options, const MotionSource& motion,
                           const drivers::ReplayClock& clock, Time start, Time end)
    : model_(options, start), motion_(motion), clock_(clock), end_(end) {}

drivers::ReadStatus SimImuDriver::Read(drivers::ImuSample* sample, Duration timeout) {
  if (!pending_) {
    next_ = model_.Next(motion_);
    pending_ = true;
  }
  if (next_.stamp >= end_) return drivers::ReadStatus::kEndOfStream;
  // A sample is only available once its time has come, as from hardware.
  if (!clock_.WaitUntilDue(next_.stamp, timeout)) return drivers::ReadStatus::kTimeout;
  *sample = next_;
  pending_ = false;
  return drivers::ReadStatus::kOk;
}

}  // namespace rover::sim
