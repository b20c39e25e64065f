#ifndef ROVER_HOST_EVAL_VIO_COMMAND_H_
#define ROVER_HOST_EVAL_VIO_COMMAND_H_

// `rover-eval vio` (issue 5): the stereo VO front end (estimator/vo
// StereoOdometry) and the local reference filter run offline, in lockstep,
// over an EuRoC-layout dataset, and are scored against its ground truth.
//
// Lockstep. The filter inputs are merged by stamp, at equal stamps in the
// order IMU, wheel speeds, clone triggers, VO results (as FilterFeed merges
// them): every IMU sample; the wheel speeds decoded from mav0/can0/data.csv
// (simulator datasets); a CloneTrigger at each stereo capture time; and the
// VO's relative pose for a frame, delivered at capture + --vo-latency-s. The
// VO processes the frames in capture order, each when its result is due, so
// nothing depends on the wall clock. No frame switches are requested: the
// filter stays in its frame 0.
//
// VO start. The filter refuses relative poses whose keyframe was captured
// before it initialised (it has no clone there), and a VO that keeps its
// first keyframe (a hovering MAV) would never be fused. So at the first frame
// captured after the filter initialised the VO is asked for a fresh keyframe
// (StereoOdometry::RequestKeyframe); its chain continues unbroken.

#include <cstdint>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "core/calib/imu_calibration.h"
#include "drivers/can/can_frame.h"
#include "drivers/replay/euroc_dataset.h"
#include "estimator/eskf/eskf_health.h"
#include "estimator/eskf/eskf_options.h"
#include "estimator/eval/trajectory_evaluation.h"
#include "estimator/vo/stereo_odometry.h"
#include "host/eval/subcommand.h"
#include "host/eval/vio_evaluation.h"

namespace rover::host::eval {

struct VioCommandOptions {
  std::string dataset_dir;          ///< the folder holding mav0/
  std::string truth_path;           ///< --gt: ground truth elsewhere (EuRoC or OpenVINS CSV)
  std::string vo_config_path;       ///< StereoOdometryOptions YAML (empty: defaults)
  std::string filter_config_path;   ///< EskfOptions YAML applied on top (empty: none)
  double vo_latency_s = 0.1;        ///< capture to delivery of a VO result [s]
  bool wheels = true;               ///< feed mav0/can0 wheel speeds if the dataset has them
  int max_frames = 0;               ///< process at most this many stereo frames (0: all)
  std::string trajectory_out_path;  ///< write the fused estimate here (EuRoC CSV)
  /// Write one CSV row per VO frame here: stamp, status, quality, stage times.
  std::string vo_log_path;
  /// Where the simulator's rover_motion.yaml and wheels.yaml (wheel geometry)
  /// are; empty: sim::DefaultSimConfigDir().
  std::string sim_config_dir;
  /// Progress on `err`: one line rewritten in place (a terminal) or a line
  /// every ~10 % of the frames.
  bool progress_in_place = false;

  /// Throws std::invalid_argument naming the first bad value.
  void Validate() const;
};

/// The simulator's wheel geometry as the filter's wheel options need it.
struct SimWheelGeometry {
  double wheel_radius_m = 0.0;
  double track_m = 0.0;
  double body_height_m = 0.0;  ///< IMU above the mean wheel contact
  double yaw_scrub_factor = 1.0;
  double slip_ratio_base = 0.0;
  double slip_ratio_per_tilt_rad = 0.0;
  std::string source;  ///< the files it was read from, for the report
};

/// Reads rover_motion.yaml and wheels.yaml from `config_dir`; a missing file
/// keeps the simulator's defaults (named in `source`). Throws ConfigError for
/// a bad file.
SimWheelGeometry LoadSimWheelGeometry(const std::string& config_dir);

/// The filter options of the command: EskfOptions defaults; the dataset IMU's
/// rate and noise densities (those that are positive); clones.max_clones =
/// kMaxClones (the VO holds 5 keyframes plus the frames in flight); wheel
/// options from `wheels` (or wheels disabled without it); then every key the
/// YAML file `filter_config_path` (if not empty) sets overrides the above.
/// Throws ConfigError (naming the file, line and key) for a bad file.
estimator::EskfOptions VioFilterOptions(const calib::ImuCalibration& imu,
                                        const std::optional<SimWheelGeometry>& wheels,
                                        const std::string& filter_config_path);

/// The VO options: defaults with checks.nominal_rate_hz = `camera_rate_hz`
/// (so dropped frames are counted), then every key of the YAML file
/// `vo_config_path` (if not empty). Throws ConfigError for a bad file and
/// std::invalid_argument for bad values.
estimator::vo::StereoOdometryOptions VioVoOptions(double camera_rate_hz,
                                                  const std::string& vo_config_path);

/// Reads mav0/can0/data.csv as the simulator writes it (hil/sim/dataset/
/// euroc_writer.h): "#timestamp [ns],id,dlc,data_hex", id as 0x-prefixed
/// hex, data as 2 hex digits per byte. Throws rover::eval::EvalError
/// "FILE:LINE: expected ..., found ..." for a malformed row.
std::vector<drivers::CanFrame> ReadCanFramesCsv(const std::string& path);

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

/// Prints the report of `run`: inputs and setup, the VO health table, the VO
/// timing table, the accuracy table (fused 4-DoF aligned, fused aligned at
/// the start, VO alone SE(3) aligned), the RPE table per segment length, the
/// relative-pose NEES table, and as the last line
///   RESULT frames=N distance_m=... ate_rmse_m=... final_err_m=... final_err_pct=...
///          rpe_trans_pct=... rpe_rot_deg_per_m=... vo_ms_p50=... vo_ms_p99=...
/// ("nan" for what cannot be computed; see AddVioCommand's help for each field).
void PrintVioReport(const VioRun& run, std::ostream& out);

/// RunVioExperiment + PrintVioReport. Returns kExitOk; kExitCheckFailed
/// (after the report) if the filter never initialised; kExitBadInput with a
/// message "rover-eval vio: ..." on `err` for unusable input.
int RunVio(const VioCommandOptions& options, std::ostream& out, std::ostream& err);

/// Adds `rover-eval vio` to `app` (see subcommand.h).
Subcommand AddVioCommand(CLI::App& app);

}  // namespace rover::host::eval

#endif  // ROVER_HOST_EVAL_VIO_COMMAND_H_
