#ifndef ROVER_HOST_EVAL_VIO_RUN_H_
#define ROVER_HOST_EVAL_VIO_RUN_H_

// One run of `rover-eval vio`: the stereo VO (estimator/vo StereoOdometry)
// and the local reference filter, offline, over an EuRoC-layout dataset, fed
// exactly as roverd's threads feed them, then scored against the dataset's
// ground truth.
//
// Feeding. The options come from the dataset's calibration through the one
// rule roverd uses (estimator/feed/filter_options.h); the inputs go through
// the one input merger (estimator/feed/input_merger.h): every IMU sample
// drives a step; before it, every input due by its stamp is handed over: the
// wheel speeds decoded from mav0/can0/data.csv (when the dataset calibrates
// the wheels), a CloneTrigger at each stereo capture, and the VO's relative
// pose for a frame, delivered at capture + --vo-latency-s. The VO processes
// a frame when its result is due, so nothing depends on the wall clock; the
// VO restarts at the filter's start by roverd's rule
// (estimator/feed/keyframe_at_filter_init.h). No frame switches are
// requested: the filter stays in its frame 0. roverd's replay board run in
// lockstep with the same latency computes the same outputs bit for bit.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "drivers/replay/euroc_dataset.h"
#include "estimator/eskf/eskf_health.h"
#include "estimator/eskf/eskf_options.h"
#include "estimator/eval/trajectory_evaluation.h"
#include "estimator/vo/stereo_odometry.h"
#include "host/eval/vio_evaluation.h"

namespace rover::host::eval {

/// RPE segment lengths of ground-truth distance [m] that a run evaluates.
inline const std::vector<double> kVioRpeSegmentsM = {1.0, 5.0, 10.0, 20.0, 50.0};

struct VioCommandOptions {
  std::string dataset_dir;         ///< the folder holding mav0/
  std::string truth_path;          ///< --gt: ground truth elsewhere (EuRoC or OpenVINS CSV)
  std::string vo_config_path;      ///< StereoOdometryOptions YAML (empty: defaults)
  std::string filter_config_path;  ///< EskfOptions YAML applied on top (empty: none)
  double vo_latency_s = 0.1;       ///< capture to delivery of a VO result [s]
  bool wheels =
      true;  ///< feed mav0/can0 wheel speeds if the dataset has them and their calibration
  int max_frames = 0;               ///< process at most this many stereo frames (0: all)
  std::string trajectory_out_path;  ///< write the fused estimate here (EuRoC CSV)
  /// Write the VO's chained poses alone here (EuRoC CSV, odometry frame: the
  /// body at the first keyframe), to see the VO's drift without the filter.
  std::string vo_trajectory_out_path;
  /// Write one CSV row per VO frame here: stamp, status, quality, stage times.
  std::string vo_log_path;
  /// Progress on `err`: one line rewritten in place (a terminal) or a line
  /// every ~10 % of the frames.
  bool progress_in_place = false;

  /// Throws std::invalid_argument naming the first bad value.
  void Validate() const;
};

/// One filter output, without the covariance (a long run has hundreds of
/// thousands).
struct VioState {
  Time stamp;
  Eigen::Vector3d p_local_body = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q_local_body = Eigen::Quaterniond::Identity();
  Eigen::Vector3d v_local_m_s = Eigen::Vector3d::Zero();
};

/// Everything one run produced, for the report and for tests.
struct VioRun {
  // Inputs.
  std::string dataset_dir;
  std::string truth_source;           ///< where the ground truth came from ("" if none)
  std::vector<std::string> notes;     ///< how the run was set up, one line each
  std::vector<std::string> issues;    ///< what the dataset loader skipped
  std::size_t frames = 0;             ///< stereo frames given to the VO
  Time first_capture;                 ///< capture time of the first frame
  std::size_t dataset_frames = 0;     ///< stereo frames in the dataset
  std::size_t unreadable_images = 0;  ///< images cv::imread could not read (passed empty)
  std::size_t imu_samples = 0;        ///< fed to the filter
  std::size_t wheel_readings = 0;     ///< fed to the filter (0: wheels off or absent)
  bool wheels_used = false;
  double vo_latency_s = 0.0;
  estimator::EskfOptions filter_options;

  // VO.
  estimator::vo::VoHealth vo_health;
  std::vector<estimator::vo::VoStageTimes> vo_times;             ///< per frame
  std::vector<estimator::RelativePoseMeasurement> measurements;  ///< as delivered
  /// 1 when the VO was asked for a fresh keyframe at the filter's
  /// initialisation (its earlier keyframes have no clone in the filter).
  int keyframe_requested_at_init = 0;
  VoChain vo_chain;

  // Filter.
  std::optional<Time> filter_init_stamp;
  uint64_t filter_outputs = 0;
  uint64_t outputs_outside_frame_0 = 0;  ///< must stay 0: no switches are requested
  estimator::EskfHealth filter_health;
  rover::eval::Trajectory fused;  ///< the filter output at each capture after init
  std::vector<VioState> states;   ///< every filter output (frame 0), in order

  // Evaluation (absent without ground truth or poses; *_error says why).
  std::optional<rover::eval::TrajectoryEvaluation> fused_evaluation;  ///< 4-DoF aligned
  std::string fused_error;
  StartAlignedErrors fused_start;  ///< 4-DoF aligned at the first pose (final_err)
  std::optional<rover::eval::TrajectoryEvaluation> vo_evaluation;  ///< SE(3) aligned
  std::string vo_error;
  StartAlignedErrors vo_start;  ///< SE(3) aligned at the first pose
  RpeQuote vo_rpe;
  std::optional<DeltaPoseNees> delta_nees;

  double wall_time_s = 0.0;
};

/// Loads the dataset, runs the VO and the filter in lockstep, evaluates
/// them, and writes the fused trajectory if asked. Progress goes to `err`.
/// Throws drivers::DatasetError, ConfigError, rover::eval::EvalError or
/// std::invalid_argument (each naming the file or option) for unusable input.
VioRun RunVioExperiment(const VioCommandOptions& options, std::ostream& err);

}  // namespace rover::host::eval

#endif  // ROVER_HOST_EVAL_VIO_RUN_H_
