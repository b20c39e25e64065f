#ifndef ROVER_HIL_SIM_DATASET_EUROC_WRITER_H_
#define ROVER_HIL_SIM_DATASET_EUROC_WRITER_H_

// Writes a dataset in the EuRoC/ASL layout, so other VIO systems run on our
// simulated worlds, plus folders for what EuRoC lacks:
//
//   mav0/imu0/{data.csv,sensor.yaml}
//   mav0/cam0|cam1/{data.csv,sensor.yaml,data/<stamp>.png}
//   mav0/state_groundtruth_estimate0/{data.csv,sensor.yaml}
//   mav0/depth0/{data.csv,sensor.yaml,data/<stamp>.png}  cam0 z-depth, uint16 mm, 0 = none
//   mav0/wheel0/data.csv    per-wheel rate and encoder ticks
//   mav0/can0/data.csv      every CAN frame (SYNC, TPDO1, heartbeat), hex payload
//   mav0/gpio0/data.csv     trigger and data-ready edges
//   mav0/tags0/data.csv     ground-truth poses of tags on moving carriers
//
// Numbers are written with 17 significant digits and files in a fixed order,
// so the same inputs give byte-identical files.

#include <opencv2/core/mat.hpp>

#include <array>
#include <fstream>
#include <memory>
#include <string>

#include "core/calib/camera_model.h"
#include "core/calib/imu_calibration.h"
#include "core/calib/wheel_calibration.h"
#include "drivers/can/can_frame.h"
#include "drivers/gpio/gpio_edge.h"
#include "drivers/imu/imu_sample.h"
#include "drivers/replay/euroc_dataset.h"

namespace rover::sim {

/// One reading of the four wheel drives (order: front-left, front-right,
/// rear-left, rear-right, as CANopen node ids 1..4).
struct WheelReading {
  Time stamp;
  std::array<double, 4> angular_velocity_rad_s{};
  std::array<int64_t, 4> encoder_ticks{};
};

class EurocWriter {
 public:
  /// Creates the folder tree under `dir` (which may exist but must not hold
  /// a mav0/ already, so a dataset is never mixed with an older one).
  explicit EurocWriter(const std::string& dir);
  ~EurocWriter();

  void WriteImuCalibration(const calib::ImuCalibration& calibration);
  /// `index` 0 or 1.
  void WriteCameraCalibration(int index, const calib::CameraModel& calibration);
  /// mav0/can0/sensor.yaml: the wheel drives' calibration
  /// (calib::LoadEurocWheels reads it).
  void WriteWheelCalibration(const calib::WheelCalibration& calibration);

  void AddImu(const drivers::ImuSample& sample);
  /// 8-bit mono images of one trigger.
  void AddStereo(Time stamp, const cv::Mat& cam0, const cv::Mat& cam1);
  /// cam0 z-depth in metres (CV_32F, 0 or non-finite = no surface).
  void AddDepth(Time stamp, const cv::Mat& depth_m);
  void AddGroundTruth(const drivers::GroundTruthState& state);
  void AddWheel(const WheelReading& reading);
  void AddCanFrame(const drivers::CanFrame& frame);
  void AddGpioEdge(const drivers::GpioEdge& edge, const char* line_name);
  /// Pose of a tag on a moving carrier at `stamp`, in the world frame.
  void AddTagPose(Time stamp, const std::string& carrier, int tag_id,
                  const Eigen::Isometry3d& T_world_tag);

  /// Flushes and closes every file; throws DatasetError on an I/O error.
  void Close();

  const std::string& dir() const { return dir_; }

 private:
  struct Files;
  std::string dir_;
  std::unique_ptr<Files> files_;
};

}  // namespace rover::sim

#endif  // ROVER_HIL_SIM_DATASET_EUROC_WRITER_H_
