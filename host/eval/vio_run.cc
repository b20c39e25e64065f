#include "host/eval/vio_run.h"

#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <stdexcept>

#include "core/calib/board_calibration.h"
#include "core/cli/report_format.h"
#include "drivers/can/wheel_speed_decoder.h"
#include "estimator/eskf/local_reference_filter.h"
#include "estimator/eval/csv_trajectory.h"
#include "estimator/eval/eval_error.h"
#include "estimator/feed/filter_options.h"
#include "estimator/feed/input_merger.h"
#include "estimator/feed/keyframe_at_filter_init.h"
#include "host/eval/can_frames_csv.h"

namespace rover::host::eval {
namespace {

namespace ev = rover::eval;
namespace vo = rover::estimator::vo;
namespace fs = std::filesystem;
using cli::Fixed;
using cli::General;

// Ground-truth samples further apart than this are not interpolated across
// (EuRoC's own ground truth is at 200 Hz, the OpenVINS CSVs at 20 Hz).
constexpr Duration kTruthMaxGap = Duration::Milliseconds(100);
// The RPE segment length RESULT quotes [m].
constexpr double kRpeQuotedM = 10.0;
// A fused pose is the first filter output at or after a capture, if it is at
// most this many IMU periods later.
constexpr double kMaxOutputLagPeriods = 1.5;

double Seconds(std::chrono::steady_clock::duration d) {
  return std::chrono::duration<double>(d).count();
}

class StateCollector final : public estimator::EskfOutputSink {
 public:
  void OnState(const estimator::EskfOutput& o) override {
    if (o.frame_id != 0) {
      ++outside_frame_0;
      return;
    }
    states.push_back({o.stamp, o.p_local_body, o.q_local_body, o.v_local_m_s});
  }
  void OnFrameSwitch(const estimator::FrameSwitchRecord&) override {}
  void OnPoseReport(const estimator::PoseReport&) override {}
  void OnReject(const estimator::RejectRecord&) override {}

  std::optional<Time> init_stamp() const {
    return states.empty() ? std::nullopt : std::optional<Time>(states.front().stamp);
  }

  std::vector<VioState> states;
  uint64_t outside_frame_0 = 0;
};

ev::PoseSample ToPoseSample(const VioState& s) {
  ev::PoseSample p;
  p.stamp = s.stamp;
  p.p_world_body = s.p_local_body;
  p.q_world_body = s.q_local_body.normalized();
  p.v_world_body_m_s = s.v_local_m_s;
  return p;
}

// Progress of the frame loop on stderr.
class Progress {
 public:
  Progress(std::ostream& err, std::size_t total, bool in_place)
      : err_(err), total_(total), in_place_(in_place), start_(std::chrono::steady_clock::now()) {}

  void Update(std::size_t done) {
    const double elapsed_s = Seconds(std::chrono::steady_clock::now() - start_);
    if (in_place_) {
      err_ << "\rrover-eval vio: frame " << done << "/" << total_ << ", " << Fixed(elapsed_s, 1)
           << " s" << (done == total_ ? "\n" : "") << std::flush;
      return;
    }
    const std::size_t decile = done * 10 / total_;
    if (decile == last_decile_) return;
    last_decile_ = decile;
    err_ << "rover-eval vio: frame " << done << "/" << total_ << " (" << decile * 10 << " %), "
         << Fixed(elapsed_s, 1) << " s\n"
         << std::flush;
  }

 private:
  std::ostream& err_;
  std::size_t total_;
  bool in_place_;
  std::chrono::steady_clock::time_point start_;
  std::size_t last_decile_ = 0;
};

// The dataset's ground truth of the IMU frame (the filter's body).
ev::Trajectory TruthTrajectory(const drivers::EurocDataset& data, const std::string& source) {
  const Eigen::Isometry3d& T_body_imu = data.calibration().imu.T_body_imu;
  ev::Trajectory truth;
  truth.set_source(source);
  for (const drivers::GroundTruthState& g : data.ground_truth()) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = g.q_world_body.normalized().toRotationMatrix();
    T.translation() = g.p_world_body;
    T = T * T_body_imu;
    ev::PoseSample s;
    s.stamp = g.stamp;
    s.p_world_body = T.translation();
    s.q_world_body = Eigen::Quaterniond(T.linear()).normalized();
    truth.Append(s);
  }
  return truth;
}

cv::Mat ReadGrey(const std::string& path, std::size_t* unreadable) {
  cv::Mat image;
  if (!path.empty()) image = cv::imread(path, cv::IMREAD_GRAYSCALE);
  if (image.empty()) ++*unreadable;
  return image;
}

std::ofstream OpenVoLog(const std::string& path) {
  std::ofstream out(path);
  if (!out) throw drivers::DatasetError(path + ": cannot open the VO log for writing");
  out << "#capture_ns,status,keyframe_points,tracked,with_right,inliers,rms_error_px,spread,"
         "inflation,new_features,total_ms,track_ms,stereo_ms,ransac_ms,refine_ms\n";
  return out;
}

void WriteVoLogRow(Time capture, const vo::VoFrameResult& r, std::ostream& out) {
  const vo::VoQuality& q = r.quality;
  out << capture.nanoseconds() << ',' << vo::VoStatusName(r.status) << ',' << q.keyframe_points
      << ',' << q.tracked << ',' << q.with_right << ',' << q.inliers << ',' << q.rms_error_px << ','
      << q.spread << ',' << q.inflation << ',' << q.new_features << ',' << r.times.total_ms << ','
      << r.times.track_ms << ',' << r.times.stereo_ms << ',' << r.times.ransac_ms << ','
      << r.times.refine_ms << '\n';
}

// The VO of the run; throws DatasetError naming `calibration_files` when the
// calibration is unusable.
vo::StereoOdometry MakeVo(const calib::CameraModel& cam0, const calib::CameraModel& cam1,
                          const vo::StereoOdometryOptions& options,
                          const std::string& calibration_files) {
  std::string error;
  std::optional<vo::StereoOdometry> made = vo::StereoOdometry::Create(cam0, cam1, options, &error);
  if (!made) {
    throw drivers::DatasetError(calibration_files +
                                ": expected a usable stereo calibration, found: " + error);
  }
  return std::move(*made);
}

// The filter output at each capture time (after initialisation).
ev::Trajectory FusedAtCaptures(const std::vector<VioState>& states,
                               const std::vector<drivers::StereoFrameFiles>& frames,
                               std::size_t frame_count, double imu_rate_hz) {
  ev::Trajectory fused;
  fused.set_source("fused estimate (filter output at each capture)");
  const Duration max_lag = Duration::FromSeconds(kMaxOutputLagPeriods / imu_rate_hz);
  for (std::size_t k = 0; k < frame_count; ++k) {
    const Time capture = frames[k].stamp;
    const auto it = std::lower_bound(states.begin(), states.end(), capture,
                                     [](const VioState& s, Time t) { return s.stamp < t; });
    if (it == states.end()) break;
    if (it->stamp - capture > max_lag) continue;
    if (!fused.empty() && it->stamp <= fused.samples().back().stamp) continue;
    fused.Append(ToPoseSample(*it));
  }
  return fused;
}

void Evaluate(const ev::Trajectory& truth, VioRun* run) {
  if (truth.empty()) {
    run->fused_error = run->vo_error = "no ground truth (pass --gt FILE)";
    run->vo_rpe.note = "no RPE: " + run->vo_error;
    return;
  }
  ev::EvaluationOptions options;
  options.association.max_gap = kTruthMaxGap;
  options.rpe.segment_lengths_m = kVioRpeSegmentsM;
  // The filter's frame is gravity-aligned: yaw and translation are unobservable.
  options.alignment.method = ev::AlignmentMethod::kFourDof;
  try {
    run->fused_evaluation = ev::EvaluateTrajectory(run->fused, truth, options);
    run->fused_start =
        EvaluateAlignedAtStart(run->fused_evaluation->aligned, ev::AlignmentMethod::kFourDof);
  } catch (const ev::EvalError& e) {
    run->fused_error = e.what();
  }
  // The VO's odometry frame is the body at its first keyframe: not gravity-aligned.
  options.alignment.method = ev::AlignmentMethod::kSe3;
  try {
    run->vo_evaluation = ev::EvaluateTrajectory(run->vo_chain.trajectory(), truth, options);
    run->vo_start = EvaluateAlignedAtStart(run->vo_evaluation->aligned, ev::AlignmentMethod::kSe3);
    run->vo_rpe =
        QuoteRpe(run->vo_evaluation->rpe, run->vo_evaluation->drift.distance_m, kRpeQuotedM);
  } catch (const ev::EvalError& e) {
    run->vo_error = e.what();
    run->vo_rpe.note = "no RPE: " + run->vo_error;
  }
  run->delta_nees = ComputeDeltaPoseNees(run->measurements, truth, kTruthMaxGap);
}

// What the run feeds the filter besides the IMU, each stream in stamp order.
struct AidingStreams {
  std::vector<estimator::WheelSpeedMeasurement> wheel_speeds;
  std::size_t next_wheel = 0;
  std::size_t next_trigger = 0;
  std::size_t next_vo = 0;
};

// The dataset's calibration as the run uses it: the wheels only when their
// speeds are fed. Notes say where everything came from.
calib::BoardCalibration RunCalibration(const drivers::EurocDataset& data,
                                       const VioCommandOptions& options, const fs::path& mav0,
                                       AidingStreams* aiding, VioRun* run) {
  calib::BoardCalibration calibration = data.calibration();
  const std::string can_path = (mav0 / "can0/data.csv").string();
  if (!options.wheels) {
    run->notes.push_back("wheels: off (--no-wheels)");
    calibration.wheels.reset();
  } else if (!fs::exists(can_path)) {
    run->notes.push_back("wheels: none (the dataset has no mav0/can0/data.csv)");
    calibration.wheels.reset();
  } else if (!calibration.wheels) {
    run->notes.push_back("wheels: not fed: " + can_path +
                         " has no wheel calibration (mav0/can0/sensor.yaml)");
  } else {
    for (const drivers::WheelSpeeds& w : drivers::DecodeWheelSpeeds(ReadCanFramesCsv(can_path))) {
      aiding->wheel_speeds.push_back({w.stamp, w.wheel_rate_rad_s});
    }
    run->notes.push_back("wheels: " + std::to_string(aiding->wheel_speeds.size()) +
                         " readings decoded from " + can_path + "; geometry and slip from " +
                         (mav0 / "can0/sensor.yaml").string());
  }
  run->wheels_used = calibration.wheels.has_value();
  return calibration;
}

}  // namespace

void VioCommandOptions::Validate() const {
  if (dataset_dir.empty()) throw std::invalid_argument("--dataset: expected a folder, found none");
  if (!(vo_latency_s >= 0.0 && vo_latency_s <= 10.0)) {
    throw std::invalid_argument("--vo-latency-s: expected a number in [0, 10], found " +
                                General(vo_latency_s));
  }
  if (max_frames < 0) {
    throw std::invalid_argument("--max-frames: expected 0 (all) or more, found " +
                                std::to_string(max_frames));
  }
}

VioRun RunVioExperiment(const VioCommandOptions& options, std::ostream& err) {
  const auto wall_start = std::chrono::steady_clock::now();
  options.Validate();
  VioRun run;
  run.dataset_dir = options.dataset_dir;
  run.vo_latency_s = options.vo_latency_s;
  const fs::path mav0 = fs::path(options.dataset_dir) / "mav0";
  const drivers::EurocDataset data =
      drivers::EurocDataset::Load(options.dataset_dir, options.truth_path);
  run.issues = data.issues();
  const std::vector<drivers::StereoFrameFiles>& frames = data.stereo_frames();
  run.dataset_frames = frames.size();
  run.frames = options.max_frames > 0
                   ? std::min(frames.size(), static_cast<std::size_t>(options.max_frames))
                   : frames.size();
  if (run.frames == 0) {
    throw drivers::DatasetError((mav0 / "cam0").string() +
                                ": expected stereo pairs with images in cam0 and cam1, found none");
  }
  run.first_capture = frames.front().stamp;
  if (data.imu().empty()) {
    throw drivers::DatasetError((mav0 / "imu0/data.csv").string() +
                                ": expected IMU samples, found none");
  }
  if (!data.ground_truth().empty()) {
    run.truth_source = options.truth_path.empty()
                           ? (mav0 / "state_groundtruth_estimate0/data.csv").string()
                           : options.truth_path;
  }
  const ev::Trajectory truth = TruthTrajectory(data, run.truth_source);

  AidingStreams aiding;
  const calib::BoardCalibration calibration = RunCalibration(data, options, mav0, &aiding, &run);
  run.filter_options =
      estimator::FilterOptionsFromCalibration(calibration, options.filter_config_path);
  run.notes.push_back("filter: from the calibration (IMU rate and noise of " +
                      (mav0 / "imu0/sensor.yaml").string() + ", max_clones " +
                      std::to_string(estimator::kMaxClones) + ")" +
                      (options.filter_config_path.empty()
                           ? std::string()
                           : ", then " + options.filter_config_path));
  if (!calibration.stereo) {
    throw drivers::DatasetError((mav0 / "cam0/sensor.yaml").string() +
                                ": expected a stereo calibration, found none");
  }
  const vo::StereoOdometryOptions vo_options =
      estimator::VoOptionsFromCalibration(calibration.stereo->cam0.rate_hz, options.vo_config_path);
  run.notes.push_back("VO: " +
                      (options.vo_config_path.empty() ? std::string("default options")
                                                      : "options from " + options.vo_config_path) +
                      ", nominal rate " + General(vo_options.checks.nominal_rate_hz) + " Hz");
  vo::StereoOdometry vo =
      MakeVo(calib::CameraInImuFrame(calibration.stereo->cam0, calibration.imu),
             calib::CameraInImuFrame(calibration.stereo->cam1, calibration.imu), vo_options,
             (mav0 / "cam0/sensor.yaml").string() + " and " + (mav0 / "cam1/sensor.yaml").string());

  // The span of the run: IMU from one initialisation window before the first
  // capture (if the dataset has it) to the delivery of the last VO result.
  const Duration latency = Duration::FromSeconds(options.vo_latency_s);
  const Time begin = frames.front().stamp - Duration::FromSeconds(run.filter_options.init.window_s);
  const Time end = frames[run.frames - 1].stamp + latency;
  const std::vector<drivers::ImuSample>& imu = data.imu();
  const auto imu_begin =
      std::lower_bound(imu.begin(), imu.end(), begin,
                       [](const drivers::ImuSample& s, Time t) { return s.stamp < t; });
  const auto imu_end = std::upper_bound(
      imu_begin, imu.end(), end, [](Time t, const drivers::ImuSample& s) { return t < s.stamp; });
  std::erase_if(aiding.wheel_speeds, [&](const estimator::WheelSpeedMeasurement& m) {
    return m.stamp < begin || m.stamp > end;
  });

  StateCollector collector;
  estimator::LocalReferenceFilter filter(run.filter_options, &collector);
  // Everything due by a sample is handed over before it: at most a few
  // inputs per sample, so a merger of roverd's size never fills.
  estimator::InputMerger<64> merger;
  const auto feed = [&filter](const estimator::EskfInput& input) { filter.Process(input); };
  const auto push = [&merger](const estimator::EskfInput& input) {
    if (!merger.Push(input)) throw std::logic_error("rover-eval vio: input merger full");
  };
  estimator::KeyframeAtFilterInit keyframe_at_init;
  Progress progress(err, run.frames, options.progress_in_place);
  std::optional<std::ofstream> vo_log;
  if (!options.vo_log_path.empty()) vo_log = OpenVoLog(options.vo_log_path);

  // Runs the VO on frame `k` (its result is due now) and hands its relative
  // pose over.
  const auto process_frame = [&](std::size_t k) {
    const drivers::StereoFrameFiles& f = frames[k];
    if (keyframe_at_init.ShouldRequest(f.stamp, collector.init_stamp())) {
      vo.RequestKeyframe();
      run.keyframe_requested_at_init = 1;
    }
    vo::StereoImages images;
    images.capture = f.stamp;
    images.sequence = k;
    images.cam0 = ReadGrey(f.cam0_path, &run.unreadable_images);
    images.cam1 = ReadGrey(f.cam1_path, &run.unreadable_images);
    const uint64_t restarts_before = vo.health().restarts;
    const vo::VoFrameResult r = vo.Process(images);
    run.vo_times.push_back(r.times);
    if (vo_log) WriteVoLogRow(f.stamp, r, *vo_log);
    const bool starts_chain =
        r.status == vo::VoStatus::kFirstKeyframe || vo.health().restarts > restarts_before;
    if (r.T_odom_body) run.vo_chain.Add(f.stamp, *r.T_odom_body, starts_chain);
    if (r.measurement) {
      estimator::RelativePoseMeasurement m = *r.measurement;
      m.stamp = f.stamp + latency;
      push(m);
      run.measurements.push_back(m);
    }
    progress.Update(k + 1);
  };
  // Hands over every aiding input stamped at or before `t`.
  const auto hand_over_due = [&](Time t) {
    for (; aiding.next_wheel < aiding.wheel_speeds.size() &&
           aiding.wheel_speeds[aiding.next_wheel].stamp <= t;
         ++aiding.next_wheel) {
      push(aiding.wheel_speeds[aiding.next_wheel]);
      ++run.wheel_readings;
    }
    for (; aiding.next_trigger < run.frames && frames[aiding.next_trigger].stamp <= t;
         ++aiding.next_trigger) {
      push(estimator::CloneTrigger{frames[aiding.next_trigger].stamp});
    }
    for (; aiding.next_vo < run.frames && frames[aiding.next_vo].stamp + latency <= t;
         ++aiding.next_vo) {
      process_frame(aiding.next_vo);
    }
  };
  for (auto sample = imu_begin; sample != imu_end; ++sample) {
    hand_over_due(sample->stamp);
    merger.Step({sample->stamp, sample->angular_velocity_rad_s, sample->linear_acceleration_m_s2},
                feed);
    ++run.imu_samples;
  }
  // What is due after the last sample still reaches the filter, as roverd's
  // Drain() feeds it at the end of a run.
  hand_over_due(Time::FromNanoseconds(std::numeric_limits<int64_t>::max()));
  merger.Drain(feed);

  run.vo_health = vo.health();
  run.filter_init_stamp = collector.init_stamp();
  run.filter_outputs = collector.states.size() + collector.outside_frame_0;
  run.outputs_outside_frame_0 = collector.outside_frame_0;
  run.filter_health = filter.health();
  run.fused = FusedAtCaptures(collector.states, frames, run.frames, run.filter_options.imu.rate_hz);
  run.states = std::move(collector.states);

  if (!options.trajectory_out_path.empty()) {
    ev::Trajectory full;
    full.mutable_samples().reserve(run.states.size());
    for (const VioState& s : run.states) full.Append(ToPoseSample(s));
    ev::WriteEurocCsvTrajectory(full, options.trajectory_out_path);
    run.notes.push_back("fused estimate (" + std::to_string(full.size()) +
                        " filter outputs, frame 0) written to " + options.trajectory_out_path +
                        " (EuRoC CSV)");
  }
  if (!options.vo_trajectory_out_path.empty()) {
    ev::WriteEurocCsvTrajectory(run.vo_chain.trajectory(), options.vo_trajectory_out_path);
    run.notes.push_back("VO chained poses (" + std::to_string(run.vo_chain.trajectory().size()) +
                        ", odometry frame) written to " + options.vo_trajectory_out_path +
                        " (EuRoC CSV)");
  }
  Evaluate(truth, &run);
  run.wall_time_s = Seconds(std::chrono::steady_clock::now() - wall_start);
  return run;
}

}  // namespace rover::host::eval
