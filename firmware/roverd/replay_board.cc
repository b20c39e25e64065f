#include "firmware/roverd/replay_board.h"

#include <stdexcept>

#include "core/calib/board_calibration.h"
#include "firmware/roverd/sensor_calibration.h"

namespace rover::roverd {

ReplayBoard::ReplayBoard(const runtime::BoardReplayOptions& options)
    : dataset_(drivers::EurocDataset::Load(options.dataset)),
      clock_(!options.lockstep,
             dataset_.imu().empty() ? Time::Zero() : dataset_.imu().front().stamp),
      imu_(dataset_, clock_),
      camera_(dataset_, clock_) {
  if (dataset_.imu().empty() || dataset_.stereo_frames().empty()) {
    throw std::invalid_argument("replay.dataset: expected IMU samples and stereo frames in " +
                                options.dataset + ", found " +
                                std::to_string(dataset_.imu().size()) + " and " +
                                std::to_string(dataset_.stereo_frames().size()));
  }
  options_.lockstep = options.lockstep;
  options_.estimator =
      FilterOptionsFromCalibration(dataset_.imu_calibration(), options.estimator_config);
  CameraSetup head;
  // The filter's body is the IMU frame.
  head.cam0 = calib::CameraInImuFrame(dataset_.cam0(), dataset_.imu_calibration());
  head.cam1 = calib::CameraInImuFrame(dataset_.cam1(), dataset_.imu_calibration());
  if (!options.vo_config.empty()) {
    head.vo = estimator::vo::StereoOdometryOptions::LoadFile(options.vo_config);
  } else if (dataset_.cam0().rate_hz > 0.0) {
    head.vo.checks.nominal_rate_hz = dataset_.cam0().rate_hz;
  }
  options_.camera = head;
}

}  // namespace rover::roverd
