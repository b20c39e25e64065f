#include "hil/sim/live/sim_stereo_camera_driver.h"

namespace rover::sim {
namespace {

drivers::ImageView ViewOf(const cv::Mat& m) {
  return {m.cols, m.rows, m.step[0], m.ptr<uint8_t>()};
}

}  // namespace

SimStereoCameraDriver::SimStereoCameraDriver(StereoRenderer& renderer,
                                             const RoverTrajectory& trajectory,
                                             const std::vector<const RoverTrajectory*>& carriers,
                                             std::size_t self, const GpioEdgeModel& triggers,
                                             const drivers::ReplayClock& clock, Time start,
                                             Time end)
    : renderer_(renderer),
      trajectory_(trajectory),
      carriers_(carriers),
      self_(self),
      triggers_(triggers),
      clock_(clock),
      start_(start),
      end_(end) {}

drivers::ReadStatus SimStereoCameraDriver::Next(drivers::StereoFrame* frame, Duration timeout) {
  const Time trigger = triggers_.CameraTriggerTime(next_index_);
  if (trigger >= end_) return drivers::ReadStatus::kEndOfStream;
  if (!clock_.WaitUntilDue(trigger, timeout)) return drivers::ReadStatus::kTimeout;
  const double t_s = (trigger - start_).ToSeconds();
  MovingCarrierPoses(carriers_, self_, t_s, &T_world_carriers_);
  renderer_.Render(PoseOf(trajectory_.Evaluate(t_s)), T_world_carriers_, next_index_, &rendered_);
  // The driver may be read from any thread, one at a time: leave the GL
  // context free for the next caller (and for the renderer's destructor).
  renderer_.ReleaseThread();
  frame->stamp = trigger;
  frame->sequence = next_index_++;
  frame->cam0 = ViewOf(rendered_.cam0);
  frame->cam1 = ViewOf(rendered_.cam1);
  return drivers::ReadStatus::kOk;
}

void SimStereoCameraDriver::Release(const drivers::StereoFrame& /*frame*/) {
  // One frame in flight: the next Render() reuses the buffers.
}

}  // namespace rover::sim
