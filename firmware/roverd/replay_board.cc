#include "firmware/roverd/replay_board.h"

#include <stdexcept>

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
  const Eigen::Isometry3d T_imu_body = dataset_.imu_calibration().T_body_imu.inverse();
  CameraSetup head;
  head.cam0 = ToCameraModel(dataset_.cam0(), T_imu_body);
  head.cam1 = ToCameraModel(dataset_.cam1(), T_imu_body);
  if (!options.vo_config.empty()) {
    head.vo = estimator::vo::StereoOdometryOptions::LoadFile(options.vo_config);
  } else if (dataset_.cam0().rate_hz > 0.0) {
    head.vo.checks.nominal_rate_hz = dataset_.cam0().rate_hz;
  }
  options_.camera = head;
}

}  // namespace rover::roverd
