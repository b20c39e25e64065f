#ifndef ROVER_DRIVERS_REPLAY_EUROC_REPLAY_H_
#define ROVER_DRIVERS_REPLAY_EUROC_REPLAY_H_

// EuRoC datasets as live sensors: an ImuDriver and a StereoCameraDriver that
// hand out the dataset's samples and frames through the same interfaces the
// hardware drivers implement. In lockstep mode they return as fast as they
// are asked; in real-time mode each item is held back until its time, offset
// so that the first item is due when replay starts.

#include <opencv2/core/mat.hpp>

#include <array>
#include <string>

#include "drivers/camera/stereo_camera_driver.h"
#include "drivers/imu/imu_driver.h"
#include "drivers/replay/euroc_dataset.h"

namespace rover::drivers {

/// Shared pacing of the replay drivers of one dataset.
class ReplayClock {
 public:
  /// `realtime` false: lockstep, never waits. `dataset_start` is the time
  /// that maps onto the moment of construction.
  ReplayClock(bool realtime, Time dataset_start);
  /// Waits until `stamp` is due or `timeout` passes; false on timeout.
  bool WaitUntilDue(Time stamp, Duration timeout) const;

 private:
  bool realtime_;
  Time dataset_start_;
  Time wall_start_;
};

class EurocImuReplay final : public ImuDriver {
 public:
  /// `dataset` and `clock` must outlive the driver.
  EurocImuReplay(const EurocDataset& dataset, const ReplayClock& clock);
  ReadStatus Read(ImuSample* sample, Duration timeout) override;

 private:
  const EurocDataset& dataset_;
  const ReplayClock& clock_;
  std::size_t next_ = 0;
};

class EurocStereoReplay final : public StereoCameraDriver {
 public:
  EurocStereoReplay(const EurocDataset& dataset, const ReplayClock& clock);
  /// kError if an image cannot be decoded or its size disagrees with the
  /// calibration; error() then says which file and why, and the frame is
  /// skipped on the next call.
  ReadStatus Next(StereoFrame* frame, Duration timeout) override;
  void Release(const StereoFrame& frame) override;
  const std::string& error() const { return error_; }

 private:
  const EurocDataset& dataset_;
  const ReplayClock& clock_;
  std::size_t next_ = 0;
  // Two decoded pairs: one the consumer holds, one being prepared.
  std::array<std::array<cv::Mat, 2>, 2> buffers_;
  std::string error_;
};

}  // namespace rover::drivers

#endif  // ROVER_DRIVERS_REPLAY_EUROC_REPLAY_H_
