#include "firmware/roverd/replay_board.h"

#include <stdexcept>

#include "core/calib/board_calibration.h"
#include "estimator/feed/filter_options.h"

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
  // The replay board plays no wheel drives back: without their speeds the
  // filter runs without wheel odometry, whatever the dataset calibrates.
  calib::BoardCalibration calibration = dataset_.calibration();
  calibration.wheels.reset();
  options_.estimator =
      estimator::FilterOptionsFromCalibration(calibration, options.estimator_config);
  CameraSetup head;
  // The filter's body is the IMU frame.
  head.cam0 = calib::CameraInImuFrame(dataset_.cam0(), calibration.imu);
  head.cam1 = calib::CameraInImuFrame(dataset_.cam1(), calibration.imu);
  head.vo = estimator::VoOptionsFromCalibration(dataset_.cam0().rate_hz, options.vo_config);
  options_.camera = head;
}

}  // namespace rover::roverd
