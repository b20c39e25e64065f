#include "firmware/roverd/replay_board.h"

#include <stdexcept>

namespace rover::roverd {
namespace {

estimator::vo::CameraModel ToCameraModel(const drivers::CameraCalibration& c,
                                         const Eigen::Isometry3d& T_imu_body) {
  estimator::vo::CameraModel m;
  m.width_px = c.width_px;
  m.height_px = c.height_px;
  m.intrinsics = c.intrinsics;
  m.distortion = c.distortion;
  m.T_body_cam = T_imu_body * c.T_body_cam;  // the filter's body is the IMU frame
  return m;
}

estimator::EskfOptions FilterOptions(const drivers::ImuCalibration& imu, const std::string& path) {
  // A given file is complete (absent keys take the defaults); without one the
  // dataset's own noise figures are the best knowledge.
  estimator::EskfOptions o =
      path.empty() ? estimator::EskfOptions{} : estimator::EskfOptions::LoadFile(path);
  // The rate is a property of the data, not a tuning choice.
  if (imu.rate_hz > 0.0) o.imu.rate_hz = imu.rate_hz;
  if (path.empty()) {
    const auto set = [](double v, double* option) {
      if (v > 0.0) *option = v;
    };
    set(imu.gyroscope_noise_density_rad_s_sqrt_hz, &o.imu.gyro_noise_density_rad_s_sqrt_hz);
    set(imu.gyroscope_random_walk_rad_s2_sqrt_hz, &o.imu.gyro_bias_random_walk_rad_s2_sqrt_hz);
    set(imu.accelerometer_noise_density_m_s2_sqrt_hz, &o.imu.accel_noise_density_m_s2_sqrt_hz);
    set(imu.accelerometer_random_walk_m_s3_sqrt_hz, &o.imu.accel_bias_random_walk_m_s3_sqrt_hz);
    o.wheels.enabled = false;  // no wheel drives are replayed
  }
  o.clones.max_clones = estimator::kMaxClones;  // 5 keyframes + frames in flight
  return o;
}

}  // namespace

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
  options_.estimator = FilterOptions(dataset_.imu_calibration(), options.estimator_config);
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
