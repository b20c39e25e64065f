#ifndef ROVER_HIL_SIM_LIVE_SIM_IMU_DRIVER_H_
#define ROVER_HIL_SIM_LIVE_SIM_IMU_DRIVER_H_

// The simulator's IMU behind the firmware's ImuDriver interface: the same
// samples a dataset would hold, handed out live, paced in real time or in
// lockstep (as fast as the consumer reads).

#include "drivers/imu/imu_driver.h"
#include "drivers/replay/euroc_replay.h"
#include "hil/sim/motion/trajectory_sample.h"
#include "hil/sim/sensors/imu_model.h"

namespace rover::sim {

class SimImuDriver final : public drivers::ImuDriver {
 public:
  /// `motion` and `clock` must outlive the driver. Samples run from `start`
  /// until `end`, then Read() returns kEndOfStream.
  SimImuDriver(const ImuModelOptions& options, const MotionSource& motion,
               const drivers::ReplayClock& clock, Time start, Time end);
  drivers::ReadStatus Read(drivers::ImuSample* sample, Duration timeout) override;

 private:
  ImuModel model_;
  const MotionSource& motion_;
  const drivers::ReplayClock& clock_;
  Time end_;
  bool pending_ = false;  // next_ was generated but was not due yet
  drivers::ImuSample next_;
};

}  // namespace rover::sim

#endif  // ROVER_HIL_SIM_LIVE_SIM_IMU_DRIVER_H_
