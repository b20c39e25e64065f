#ifndef ROVER_DRIVERS_REPLAY_EUROC_DATASET_H_
#define ROVER_DRIVERS_REPLAY_EUROC_DATASET_H_

// Reader for datasets in the EuRoC/ASL layout (ETH Zurich's MAV datasets, and
// what `rover-sim generate` writes):
//
//   DIR/mav0/imu0/{data.csv,sensor.yaml}
//   DIR/mav0/cam0/{data.csv,sensor.yaml,data/<stamp>.png}    (and cam1)
//   DIR/mav0/state_groundtruth_estimate0/data.csv            (optional)
//
// Everything is validated on load. A malformed line, a non-monotonic
// timestamp or a calibration with the wrong shape is an error naming the file
// and line; a camera row whose image file does not exist is not an error but
// is reported in `issues()` and left out, as are frames that have no partner
// in the other camera.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/time/time.h"
#include "drivers/imu/imu_sample.h"

namespace rover::drivers {

/// A dataset that cannot be read; the message names the file and line.
class DatasetError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Pinhole + radial-tangential calibration of one camera (EuRoC sensor.yaml).
struct CameraCalibration {
  int width_px = 0;
  int height_px = 0;
  double rate_hz = 0.0;
  std::array<double, 4> intrinsics{};  ///< fu, fv, cu, cv [px]
  std::array<double, 4> distortion{};  ///< k1, k2, p1, p2 (radial-tangential)
  Eigen::Isometry3d T_body_cam = Eigen::Isometry3d::Identity();  ///< EuRoC's T_BS
};

/// IMU noise figures (EuRoC sensor.yaml).
struct ImuCalibration {
  double rate_hz = 0.0;
  double gyroscope_noise_density_rad_s_sqrt_hz = 0.0;
  double gyroscope_random_walk_rad_s2_sqrt_hz = 0.0;
  double accelerometer_noise_density_m_s2_sqrt_hz = 0.0;
  double accelerometer_random_walk_m_s3_sqrt_hz = 0.0;
  Eigen::Isometry3d T_body_imu = Eigen::Isometry3d::Identity();
};

/// A stereo pair: both images share one timestamp.
struct StereoFrameFiles {
  Time stamp;
  std::string cam0_path;
  std::string cam1_path;
};

/// Ground truth of the body (IMU) in the dataset's world frame.
struct GroundTruthState {
  Time stamp;
  Eigen::Vector3d p_world_body;
  Eigen::Quaterniond q_world_body;
  Eigen::Vector3d v_world_body_m_s;
  Eigen::Vector3d gyro_bias_rad_s;
  Eigen::Vector3d accel_bias_m_s2;
};

class EurocDataset {
 public:
  /// Loads DIR (the folder that contains mav0/). `ground_truth_csv`, if not
  /// empty, replaces mav0/state_groundtruth_estimate0/data.csv; it may be in
  /// the EuRoC or the OpenVINS CSV layout (same column order). Throws
  /// DatasetError on anything it cannot use.
  static EurocDataset Load(const std::string& dir, const std::string& ground_truth_csv = "");

  const std::string& dir() const { return dir_; }
  const std::vector<ImuSample>& imu() const { return imu_; }
  const std::vector<StereoFrameFiles>& stereo_frames() const { return frames_; }
  const std::vector<GroundTruthState>& ground_truth() const { return ground_truth_; }
  const CameraCalibration& cam0() const { return cam0_; }
  const CameraCalibration& cam1() const { return cam1_; }
  const ImuCalibration& imu_calibration() const { return imu_calibration_; }
  /// Things that were skipped while loading (missing images, unpaired rows).
  const std::vector<std::string>& issues() const { return issues_; }

  /// Ground truth interpolated at `t` (linear position/velocity, slerp), or
  /// nullopt outside its time span or across a gap larger than `max_gap`.
  std::optional<GroundTruthState> GroundTruthAt(
      Time t, Duration max_gap = Duration::Milliseconds(100)) const;

 private:
  std::string dir_;
  std::vector<ImuSample> imu_;
  std::vector<StereoFrameFiles> frames_;
  std::vector<GroundTruthState> ground_truth_;
  CameraCalibration cam0_, cam1_;
  ImuCalibration imu_calibration_;
  std::vector<std::string> issues_;
};

/// Reads an EuRoC camera sensor.yaml (OpenCV FileStorage YAML).
CameraCalibration LoadCameraCalibration(const std::string& sensor_yaml);
/// Reads an EuRoC IMU sensor.yaml.
ImuCalibration LoadImuCalibration(const std::string& sensor_yaml);

}  // namespace rover::drivers

#endif  // ROVER_DRIVERS_REPLAY_EUROC_DATASET_H_
