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
// in the other camera. The sensor.yaml files are read by core/calib
// (euroc_sensor_yaml.h) into one calib::BoardCalibration.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/calib/board_calibration.h"
#include "core/time/time.h"
#include "drivers/imu/imu_sample.h"

namespace rover::drivers {

/// A dataset that cannot be read; the message names the file and line.
class DatasetError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
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
  /// The dataset's calibration (imu0, cam0, cam1 sensor.yaml): always with a
  /// stereo head, never with wheels.
  const calib::BoardCalibration& calibration() const { return calibration_; }
  /// Shorthands for calibration().stereo->cam0, ->cam1 and .imu.
  const calib::CameraModel& cam0() const { return calibration_.stereo->cam0; }
  const calib::CameraModel& cam1() const { return calibration_.stereo->cam1; }
  const calib::ImuCalibration& imu_calibration() const { return calibration_.imu; }
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
  calib::BoardCalibration calibration_;
  std::vector<std::string> issues_;
};

}  // namespace rover::drivers

#endif  // ROVER_DRIVERS_REPLAY_EUROC_DATASET_H_
