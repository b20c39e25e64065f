#ifndef ROVER_HIL_SIM_LIVE_SIM_STEREO_CAMERA_DRIVER_H_
#define ROVER_HIL_SIM_LIVE_SIM_STEREO_CAMERA_DRIVER_H_

// The simulated stereo pair behind the firmware's StereoCameraDriver
// interface: at each trigger edge of the GPIO model the renderer draws the
// pair at the rover's pose; the frame carries the trigger time.

#include <vector>

#include "drivers/camera/stereo_camera_driver.h"
#include "drivers/replay/euroc_replay.h"
#include "hil/sim/motion/rover_trajectory.h"
#include "hil/sim/render/stereo_renderer.h"
#include "hil/sim/sensors/gpio_edge_model.h"

namespace rover::sim {

class SimStereoCameraDriver final : public drivers::StereoCameraDriver {
 public:
  /// Everything passed by reference must outlive the driver. `carriers` are
  /// the trajectories of the world's moving tag carriers, in world order;
  /// carrier `self` (or kNoHiddenCarrier) is this rover's own.
  SimStereoCameraDriver(StereoRenderer& renderer, const RoverTrajectory& trajectory,
                        const std::vector<const RoverTrajectory*>& carriers, std::size_t self,
                        const GpioEdgeModel& triggers, const drivers::ReplayClock& clock,
                        Time start, Time end);
  drivers::ReadStatus Next(drivers::StereoFrame* frame, Duration timeout) override;
  void Release(const drivers::StereoFrame& frame) override;

 private:
  StereoRenderer& renderer_;
  const RoverTrajectory& trajectory_;
  const std::vector<const RoverTrajectory*>& carriers_;
  std::size_t self_;
  const GpioEdgeModel& triggers_;
  const drivers::ReplayClock& clock_;
  Time start_;
  Time end_;
  uint64_t next_index_ = 0;
  RenderedStereoFrame rendered_;
  std::vector<Eigen::Isometry3d> T_world_carriers_;
};

}  // namespace rover::sim

#endif  // ROVER_HIL_SIM_LIVE_SIM_STEREO_CAMERA_DRIVER_H_
