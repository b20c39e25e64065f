#include "host/eval/vio_command.h"

#include <unistd.h>

#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <array>
#include <charconv>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <memory>
#include <stdexcept>

#include "core/calib/board_calibration.h"
#include "core/config/config.h"
#include "estimator/eskf/local_reference_filter.h"
#include "estimator/eval/csv_trajectory.h"
#include "estimator/eval/eval_error.h"
#include "estimator/eval/text_table_reader.h"
#include "hil/sim/estimator_feed/filter_feed.h"
#include "hil/sim/motion/rover_trajectory.h"
#include "hil/sim/scenario/scenario.h"
#include "hil/sim/sensors/wheel_odometry_model.h"
#include "host/eval/report_format.h"

namespace rover::host::eval {
namespace {

namespace ev = rover::eval;
namespace vo = rover::estimator::vo;
namespace fs = std::filesystem;
using estimator::EskfOptions;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// Ground-truth samples further apart than this are not interpolated across
// (EuRoC's own ground truth is at 200 Hz, the OpenVINS CSVs at 20 Hz).
constexpr Duration kTruthMaxGap = Duration::Milliseconds(100);
// RPE segment lengths of ground-truth distance [m], and the one RESULT quotes.
const std::vector<double> kRpeSegmentsM = {1.0, 5.0, 10.0, 20.0, 50.0};
constexpr double kRpeQuotedM = 10.0;
// A fused pose is the first filter output at or after a capture, if it is at
// most this many IMU periods later.
constexpr double kMaxOutputLagPeriods = 1.5;
// Dataset issues listed in the report at most.
constexpr std::size_t kMaxIssueLines = 10;
// Below this spread of the fused positions the alignment yaw is fitted to noise.
constexpr double kMinAlignmentSpreadM = 0.5;

double Seconds(std::chrono::steady_clock::duration d) {
  return std::chrono::duration<double>(d).count();
}

// True if the YAML document `root` sets `section`.`key`.
bool FileSets(const ConfigNode& root, const char* section, const char* key) {
  return root.Has(section) && root.Child(section).Has(key);
}

// The filter's estimate at IMU rate, without the covariance (a long run has
// hundreds of thousands of outputs).
struct StateRecord {
  Time stamp;
  Eigen::Vector3d p_local_body;
  Eigen::Quaterniond q_local_body;
  Eigen::Vector3d v_local_m_s;
};

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

  std::vector<StateRecord> states;
  uint64_t outside_frame_0 = 0;
};

ev::PoseSample ToPoseSample(const StateRecord& s) {
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
  const Eigen::Isometry3d& T_body_imu = data.imu_calibration().T_body_imu;
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

bool ParseHex(std::string_view text, uint32_t* value) {
  if (text.size() > 2 && text[0] == '0' && (text[1] == 'x' || text[1] == 'X'))
    text.remove_prefix(2);
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, *value, 16);
  return !text.empty() && ec == std::errc() && ptr == end;
}

// Frames, wheel readings and IMU samples of the run, in the merge order.
enum Stream { kImuStream, kWheelStream, kTriggerStream, kVoStream, kStreamCount };

// The stream with the earliest head; at equal stamps the lower Stream value.
// kStreamCount when every stream is exhausted.
std::size_t NextStream(const std::array<std::optional<Time>, kStreamCount>& heads) {
  std::size_t next = kStreamCount;
  for (std::size_t s = 0; s < heads.size(); ++s) {
    if (heads[s] && (next == kStreamCount || *heads[s] < *heads[next])) next = s;
  }
  return next;
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
ev::Trajectory FusedAtCaptures(const std::vector<StateRecord>& states,
                               const std::vector<drivers::StereoFrameFiles>& frames,
                               std::size_t frame_count, double imu_rate_hz) {
  ev::Trajectory fused;
  fused.set_source("fused estimate (filter output at each capture)");
  const Duration max_lag = Duration::FromSeconds(kMaxOutputLagPeriods / imu_rate_hz);
  for (std::size_t k = 0; k < frame_count; ++k) {
    const Time capture = frames[k].stamp;
    const auto it = std::lower_bound(states.begin(), states.end(), capture,
                                     [](const StateRecord& s, Time t) { return s.stamp < t; });
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
  options.rpe.segment_lengths_m = kRpeSegmentsM;
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

SimWheelGeometry LoadSimWheelGeometry(const std::string& config_dir) {
  // rover-sim generate drives the default RoverTrajectoryOptions, which
  // rover_motion.yaml mirrors.
  sim::RoverTrajectoryOptions rover;
  sim::WheelOdometryOptions wheels;
  std::string sources;
  const std::string motion_path = (fs::path(config_dir) / "rover_motion.yaml").string();
  if (fs::exists(motion_path)) {
    const ConfigNode root = ConfigNode::LoadFile(motion_path);
    rover = sim::RoverTrajectoryOptions::Load(root);
    root.CheckNoUnknownKeysRecursive();
    sources = motion_path;
  } else {
    sources = "the simulator's rover defaults (no " + motion_path + ")";
  }
  const std::string wheels_path = (fs::path(config_dir) / "wheels.yaml").string();
  if (fs::exists(wheels_path)) {
    wheels = sim::WheelOdometryOptions::LoadFile(wheels_path);
    sources += ", " + wheels_path;
  } else {
    sources += ", the wheel model's defaults (no " + wheels_path + ")";
  }
  SimWheelGeometry g;
  g.wheel_radius_m = rover.wheel_radius_m;
  g.track_m = rover.track_m;
  g.body_height_m = rover.body_height_m;
  g.yaw_scrub_factor = wheels.yaw_scrub_factor;
  g.slip_ratio_base = wheels.slip_base_ratio;
  g.slip_ratio_per_tilt_rad = wheels.slip_slope_gain_per_rad;
  g.source = sources;
  return g;
}

EskfOptions VioFilterOptions(const calib::ImuCalibration& imu,
                             const std::optional<SimWheelGeometry>& wheels,
                             const std::string& filter_config_path) {
  EskfOptions base;
  if (imu.rate_hz > 0.0) base.imu.rate_hz = imu.rate_hz;
  const auto set_if_positive = [](double value, double* option) {
    if (value > 0.0) *option = value;
  };
  set_if_positive(imu.gyro_noise_density_rad_s_sqrt_hz, &base.imu.gyro_noise_density_rad_s_sqrt_hz);
  set_if_positive(imu.gyro_random_walk_rad_s2_sqrt_hz,
                  &base.imu.gyro_bias_random_walk_rad_s2_sqrt_hz);
  set_if_positive(imu.accel_noise_density_m_s2_sqrt_hz, &base.imu.accel_noise_density_m_s2_sqrt_hz);
  set_if_positive(imu.accel_random_walk_m_s3_sqrt_hz,
                  &base.imu.accel_bias_random_walk_m_s3_sqrt_hz);
  base.clones.max_clones = estimator::kMaxClones;
  base.wheels.enabled = wheels.has_value();
  if (wheels) {
    // As EskfOptionsForFeed (hil/sim/estimator_feed/filter_run.cc) sets them
    // for the simulated rover.
    base.wheels.wheel_radius_m = wheels->wheel_radius_m;
    base.wheels.track_m = wheels->track_m;
    base.wheels.yaw_scrub_factor = wheels->yaw_scrub_factor;
    // The mean of the four wheel centres (RoverTrajectory::WheelCenterBody).
    base.wheels.lever_arm_body_m = {0.0, 0.0, wheels->wheel_radius_m - wheels->body_height_m};
    base.wheels.nonholonomic_point_body_m = Eigen::Vector3d::Zero();
    base.wheels.slip_ratio_base = wheels->slip_ratio_base;
    base.wheels.slip_ratio_per_tilt_rad = wheels->slip_ratio_per_tilt_rad;
  }
  if (filter_config_path.empty()) return base;

  const ConfigNode root = ConfigNode::LoadFile(filter_config_path);
  EskfOptions o = EskfOptions::Load(root);
  root.CheckNoUnknownKeysRecursive();
  // Load() filled every absent key with its default: put back what the
  // command derived from the dataset unless the file sets it.
  const auto keep = [&](const char* section, const char* key, auto group, auto field) {
    if (!FileSets(root, section, key)) (o.*group).*field = (base.*group).*field;
  };
  using estimator::ImuNoiseOptions;
  using estimator::WheelOdometryOptions;
  keep("imu", "rate_hz", &EskfOptions::imu, &ImuNoiseOptions::rate_hz);
  keep("imu", "gyro_noise_density_rad_s_sqrt_hz", &EskfOptions::imu,
       &ImuNoiseOptions::gyro_noise_density_rad_s_sqrt_hz);
  keep("imu", "gyro_bias_random_walk_rad_s2_sqrt_hz", &EskfOptions::imu,
       &ImuNoiseOptions::gyro_bias_random_walk_rad_s2_sqrt_hz);
  keep("imu", "accel_noise_density_m_s2_sqrt_hz", &EskfOptions::imu,
       &ImuNoiseOptions::accel_noise_density_m_s2_sqrt_hz);
  keep("imu", "accel_bias_random_walk_m_s3_sqrt_hz", &EskfOptions::imu,
       &ImuNoiseOptions::accel_bias_random_walk_m_s3_sqrt_hz);
  keep("clones", "max_clones", &EskfOptions::clones, &estimator::CloneOptions::max_clones);
  keep("wheels", "enabled", &EskfOptions::wheels, &WheelOdometryOptions::enabled);
  keep("wheels", "wheel_radius_m", &EskfOptions::wheels, &WheelOdometryOptions::wheel_radius_m);
  keep("wheels", "track_m", &EskfOptions::wheels, &WheelOdometryOptions::track_m);
  keep("wheels", "yaw_scrub_factor", &EskfOptions::wheels, &WheelOdometryOptions::yaw_scrub_factor);
  keep("wheels", "lever_arm_body_m", &EskfOptions::wheels, &WheelOdometryOptions::lever_arm_body_m);
  keep("wheels", "nonholonomic_point_body_m", &EskfOptions::wheels,
       &WheelOdometryOptions::nonholonomic_point_body_m);
  keep("wheels", "slip_ratio_base", &EskfOptions::wheels, &WheelOdometryOptions::slip_ratio_base);
  keep("wheels", "slip_ratio_per_tilt_rad", &EskfOptions::wheels,
       &WheelOdometryOptions::slip_ratio_per_tilt_rad);
  return o;
}

vo::StereoOdometryOptions VioVoOptions(double camera_rate_hz, const std::string& vo_config_path) {
  vo::StereoOdometryOptions o;
  bool rate_from_file = false;
  if (!vo_config_path.empty()) {
    const ConfigNode root = ConfigNode::LoadFile(vo_config_path);
    o = vo::StereoOdometryOptions::Load(root);
    root.CheckNoUnknownKeysRecursive();
    rate_from_file = FileSets(root, "checks", "nominal_rate_hz");
  }
  if (!rate_from_file && camera_rate_hz > 0.0) o.checks.nominal_rate_hz = camera_rate_hz;
  o.Validate();
  return o;
}

std::vector<drivers::CanFrame> ReadCanFramesCsv(const std::string& path) {
  ev::TextTableReader csv(path, ev::TextTableReader::Separator::kComma);
  std::vector<drivers::CanFrame> frames;
  std::vector<std::string_view> c;
  while (csv.Next(&c)) {
    if (c.size() != 3 && c.size() != 4) {
      csv.Fail("expected 4 columns (timestamp [ns], id, dlc, data_hex), found " +
               std::to_string(c.size()));
    }
    drivers::CanFrame f;
    f.stamp = csv.Nanoseconds(c[0], "timestamp");
    if (!ParseHex(c[1], &f.id) || f.id > 0x7FF) {
      csv.Fail("expected an 11-bit identifier such as 0x181 for id, found '" + std::string(c[1]) +
               "'");
    }
    const int64_t dlc = csv.Int64(c[2], "dlc");
    if (dlc < 0 || dlc > 8) csv.Fail("expected a dlc in [0, 8], found " + std::to_string(dlc));
    f.dlc = static_cast<uint8_t>(dlc);
    const std::string_view hex = c.size() == 4 ? c[3] : std::string_view();
    if (hex.size() != 2 * f.dlc) {
      csv.Fail("expected " + std::to_string(2 * f.dlc) + " hex digits of data for dlc " +
               std::to_string(dlc) + ", found '" + std::string(hex) + "'");
    }
    for (std::size_t b = 0; b < f.dlc; ++b) {
      uint32_t byte = 0;
      if (!ParseHex(hex.substr(2 * b, 2), &byte)) {
        csv.Fail("expected hex digits for data_hex, found '" + std::string(hex) + "'");
      }
      f.data[b] = static_cast<uint8_t>(byte);
    }
    frames.push_back(f);
  }
  return frames;
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

  // Wheels (simulator datasets).
  const std::string can_path = (mav0 / "can0/data.csv").string();
  std::optional<SimWheelGeometry> geometry;
  std::vector<estimator::WheelSpeedMeasurement> wheel_speeds;
  if (!options.wheels) {
    run.notes.push_back("wheels: off (--no-wheels)");
  } else if (!fs::exists(can_path)) {
    run.notes.push_back("wheels: none (the dataset has no mav0/can0/data.csv)");
  } else {
    wheel_speeds = sim::DecodeWheelSpeeds(ReadCanFramesCsv(can_path));
    geometry = LoadSimWheelGeometry(options.sim_config_dir.empty() ? sim::DefaultSimConfigDir()
                                                                   : options.sim_config_dir);
    run.notes.push_back("wheels: " + std::to_string(wheel_speeds.size()) +
                        " readings decoded from " + can_path + "; geometry and slip from " +
                        geometry->source);
  }
  run.wheels_used = geometry.has_value();

  run.filter_options =
      VioFilterOptions(data.imu_calibration(), geometry, options.filter_config_path);
  run.notes.push_back(
      "filter: defaults, IMU rate and noise from " + (mav0 / "imu0/sensor.yaml").string() +
      ", max_clones " + std::to_string(estimator::kMaxClones) +
      (options.filter_config_path.empty() ? std::string()
                                          : ", then " + options.filter_config_path));
  const vo::StereoOdometryOptions vo_options =
      VioVoOptions(data.cam0().rate_hz, options.vo_config_path);
  run.notes.push_back("VO: " +
                      (options.vo_config_path.empty() ? std::string("default options")
                                                      : "options from " + options.vo_config_path) +
                      ", nominal rate " + General(vo_options.checks.nominal_rate_hz) + " Hz");

  // The filter's body is the IMU frame.
  vo::StereoOdometry vo =
      MakeVo(calib::CameraInImuFrame(data.cam0(), data.imu_calibration()),
             calib::CameraInImuFrame(data.cam1(), data.imu_calibration()), vo_options,
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
  std::erase_if(wheel_speeds, [&](const estimator::WheelSpeedMeasurement& m) {
    return m.stamp < begin || m.stamp > end;
  });

  StateCollector collector;
  estimator::LocalReferenceFilter filter(run.filter_options, &collector);
  Progress progress(err, run.frames, options.progress_in_place);
  auto next_imu = imu_begin;
  std::size_t next_wheel = 0, next_trigger = 0, next_vo = 0;
  bool vo_started_after_init = false;
  std::optional<std::ofstream> vo_log;
  if (!options.vo_log_path.empty()) vo_log = OpenVoLog(options.vo_log_path);
  for (;;) {
    std::array<std::optional<Time>, kStreamCount> heads;
    if (next_imu != imu_end) heads[kImuStream] = next_imu->stamp;
    if (next_wheel < wheel_speeds.size()) heads[kWheelStream] = wheel_speeds[next_wheel].stamp;
    if (next_trigger < run.frames) heads[kTriggerStream] = frames[next_trigger].stamp;
    if (next_vo < run.frames) heads[kVoStream] = frames[next_vo].stamp + latency;
    const std::size_t stream = NextStream(heads);
    if (stream == kImuStream) {
      estimator::ImuMeasurement m;
      m.stamp = next_imu->stamp;
      m.angular_velocity_rad_s = next_imu->angular_velocity_rad_s;
      m.linear_acceleration_m_s2 = next_imu->linear_acceleration_m_s2;
      filter.AddImu(m);
      ++next_imu;
      ++run.imu_samples;
    } else if (stream == kWheelStream) {
      filter.AddWheelSpeeds(wheel_speeds[next_wheel++]);
      ++run.wheel_readings;
    } else if (stream == kTriggerStream) {
      filter.AddCloneTrigger({frames[next_trigger++].stamp});
    } else if (stream == kVoStream) {
      const drivers::StereoFrameFiles& f = frames[next_vo];
      const std::optional<Time> init = collector.init_stamp();
      if (!vo_started_after_init && init && *init <= f.stamp) {
        // The filter holds clones only from its start: the VO's keyframes
        // from before are useless to it, so ask for a fresh one.
        vo_started_after_init = true;
        if (next_vo > 0) {
          vo.RequestKeyframe();
          run.keyframe_requested_at_init = 1;
        }
      }
      vo::StereoImages images;
      images.capture = f.stamp;
      images.sequence = next_vo;
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
        filter.AddRelativePose(m);
        run.measurements.push_back(m);
      }
      ++next_vo;
      progress.Update(next_vo);
    } else {
      break;
    }
  }
  run.vo_health = vo.health();
  run.filter_init_stamp = collector.init_stamp();
  run.filter_outputs = collector.states.size() + collector.outside_frame_0;
  run.outputs_outside_frame_0 = collector.outside_frame_0;
  run.filter_health = filter.health();
  run.fused = FusedAtCaptures(collector.states, frames, run.frames, run.filter_options.imu.rate_hz);

  if (!options.trajectory_out_path.empty()) {
    ev::Trajectory full;
    full.mutable_samples().reserve(collector.states.size());
    for (const StateRecord& s : collector.states) full.Append(ToPoseSample(s));
    ev::WriteEurocCsvTrajectory(full, options.trajectory_out_path);
    run.notes.push_back("fused estimate (" + std::to_string(full.size()) +
                        " filter outputs, frame 0) written to " + options.trajectory_out_path +
                        " (EuRoC CSV)");
  }
  Evaluate(truth, &run);
  run.wall_time_s = Seconds(std::chrono::steady_clock::now() - wall_start);
  return run;
}

namespace {

void PrintVoHealth(const VioRun& run, std::ostream& out) {
  const vo::VoHealth& h = run.vo_health;
  out << "\nVO health (" << run.frames << " frames)\n";
  TextTable table({"status", "frames"});
  for (std::size_t s = 0; s < h.by_status.size(); ++s) {
    table.AddRow({vo::VoStatusName(static_cast<vo::VoStatus>(s)), std::to_string(h.by_status[s])});
  }
  out << table.ToString();
  const estimator::EskfHealth& f = run.filter_health;
  const auto kind = estimator::InputKind::kRelativePose;
  std::string reasons;
  for (int c = 0; c < estimator::kRejectReasonCount; ++c) {
    const auto reason = static_cast<estimator::RejectReason>(c);
    if (f.Rejected(kind, reason) == 0) continue;
    reasons += std::string(reasons.empty() ? "" : ", ") + estimator::ToString(reason) + " " +
               std::to_string(f.Rejected(kind, reason));
  }
  out << "  measurements " << h.measurements << " (inflated covariance " << h.inflated
      << "), filter accepted " << f.Accepted(kind) << ", rejected " << f.Rejected(kind)
      << (reasons.empty() ? "" : " (" + reasons + ")") << "\n";
  out << "  keyframes " << h.keyframes << ", revisits " << h.revisits << ", chain restarts "
      << run.vo_chain.restarts() << " (after tracking loss " << h.restarts
      << "), keyframe requested at filter initialisation " << run.keyframe_requested_at_init
      << "\n";
  out << "  dropped frames (capture gaps) " << h.dropped_frames << ", missing right image "
      << h.missing_right << ", unreadable images " << run.unreadable_images << "\n";
}

void PrintVoTiming(const VioRun& run, std::ostream& out) {
  out << "\nVO time per frame [ms] (" << run.vo_times.size() << " frames, wall clock)\n";
  TextTable table({"stage", "median", "p99", "max"});
  const auto row = [&](const char* name, double vo::VoStageTimes::*stage) {
    std::vector<double> v;
    v.reserve(run.vo_times.size());
    for (const vo::VoStageTimes& t : run.vo_times) v.push_back(t.*stage);
    table.AddRow({name, Fixed(Percentile(v, 50.0), 2), Fixed(Percentile(v, 99.0), 2),
                  Fixed(Percentile(v, 100.0), 2)});
  };
  row("check", &vo::VoStageTimes::check_ms);
  row("rectify", &vo::VoStageTimes::rectify_ms);
  row("pyramid", &vo::VoStageTimes::pyramid_ms);
  row("track", &vo::VoStageTimes::track_ms);
  row("stereo", &vo::VoStageTimes::stereo_ms);
  row("detect", &vo::VoStageTimes::detect_ms);
  row("ransac", &vo::VoStageTimes::ransac_ms);
  row("refine", &vo::VoStageTimes::refine_ms);
  row("total", &vo::VoStageTimes::total_ms);
  out << table.ToString();
}

void PrintAccuracy(const VioRun& run, std::ostream& out) {
  out << "\nAccuracy against ground truth\n";
  TextTable table({"estimate", "aligned", "poses", "distance [m]", "ATE rmse [m]", "ATE max [m]",
                   "rot rmse [deg]", "final [m]", "final [%]"});
  const auto row = [&](const char* name, const std::string& alignment,
                       const std::optional<ev::TrajectoryEvaluation>& e, const ev::AteResult& ate,
                       double final_m) {
    const double distance = e ? e->drift.distance_m : kNaN;
    table.AddRow({name, alignment, std::to_string(e ? e->aligned.size() : 0), Fixed(distance, 3),
                  Fixed(ate.position_m.rmse, 4), Fixed(ate.position_m.max, 4),
                  Fixed(ate.rotation_deg.rmse, 3), Fixed(final_m, 4),
                  Fixed(distance > 0.0 ? 100.0 * final_m / distance : kNaN, 3)});
  };
  const std::optional<ev::TrajectoryEvaluation>& fused = run.fused_evaluation;
  const std::optional<ev::TrajectoryEvaluation>& vo = run.vo_evaluation;
  const ev::AteResult none;
  row("fused", "4dof, all poses", fused, fused ? fused->ate : none,
      fused ? fused->drift.final_error_m : kNaN);
  row("fused", "4dof, first pose", fused, run.fused_start.ate, run.fused_start.final_error_m);
  row("VO alone", "se3, all poses", vo, vo ? vo->ate : none, vo ? vo->drift.final_error_m : kNaN);
  row("VO alone", "se3, first pose", vo, run.vo_start.ate, run.vo_start.final_error_m);
  out << table.ToString();
  if (!run.fused_error.empty()) out << "  fused: not evaluated: " << run.fused_error << "\n";
  if (!run.vo_error.empty()) out << "  VO alone: not evaluated: " << run.vo_error << "\n";
  for (const auto* e : {&fused, &vo}) {
    if (*e && (*e)->alignment.spread_m < kMinAlignmentSpreadM) {
      out << "  note: the " << (e == &fused ? "fused" : "VO") << " positions spread only "
          << Fixed((*e)->alignment.spread_m, 3)
          << " m around their centroid: the rotation of the all-poses alignment is fitted to "
             "noise\n";
    }
  }
  out << "  fused: the filter output at each capture after initialisation (frame 0); VO alone: "
         "its chained poses. ate_rmse_m in RESULT: fused, 4dof, all poses; final_err_m: fused, "
         "4dof, first pose\n";
}

void PrintRpe(const VioRun& run, std::ostream& out) {
  out << "\nRelative pose error per segment length (ground-truth distance; mean over segments)\n";
  TextTable table({"segment [m]", "VO segments", "VO trans [%]", "VO rot [deg/m]", "fused segments",
                   "fused trans [%]", "fused rot [deg/m]"});
  for (std::size_t i = 0; i < kRpeSegmentsM.size(); ++i) {
    std::vector<std::string> cells = {General(kRpeSegmentsM[i])};
    if (kRpeSegmentsM[i] == run.vo_rpe.length_m) cells[0] += " *";
    for (const auto* e : {&run.vo_evaluation, &run.fused_evaluation}) {
      if (!*e) {
        cells.insert(cells.end(), {"0", "nan", "nan"});
        continue;
      }
      const ev::RpeSegmentResult& s = (*e)->rpe.segments[i];
      cells.insert(cells.end(),
                   {std::to_string(s.translation_pct.count), Fixed(s.translation_pct.mean, 3),
                    Fixed(s.rotation_deg_per_m.mean, 4)});
    }
    table.AddRow(cells);
  }
  out << table.ToString();
  out << "  (* VO alone, in RESULT) " << run.vo_rpe.note << "\n";
}

void PrintDeltaPoseNees(const VioRun& run, std::ostream& out) {
  if (!run.delta_nees) {
    out << "\nRelative-pose NEES: no ground truth\n";
    return;
  }
  const DeltaPoseNees& d = *run.delta_nees;
  const ev::NeesResult& n = d.nees;
  out << "\nNEES of the VO's relative poses against ground truth (" << n.samples.size() << " of "
      << d.measurements << " measurements; " << d.without_truth << " without ground truth, "
      << n.singular << " with a covariance not positive definite)\n";
  TextTable table(
      {"", "dof", "mean", "95% bounds of the mean", "inside", "samples in 95% interval"});
  const auto bounds = [](const ev::ChiSquareInterval& b) {
    return "[" + Fixed(b.lower, 3) + ", " + Fixed(b.upper, 3) + "]";
  };
  const auto inside = [](double mean, const ev::ChiSquareInterval& b) {
    return std::isnan(mean) ? "-" : (mean >= b.lower && mean <= b.upper ? "yes" : "NO");
  };
  table.AddRow({"pose", "6", Fixed(n.mean_pose, 3), bounds(d.bounds_6dof),
                inside(n.mean_pose, d.bounds_6dof), "-"});
  table.AddRow({"translation", "3", Fixed(n.mean_position, 3), bounds(d.bounds_3dof),
                inside(n.mean_position, d.bounds_3dof), Fixed(100.0 * n.position_in_95, 1) + " %"});
  table.AddRow({"rotation", "3", Fixed(n.mean_attitude, 3), bounds(d.bounds_3dof),
                inside(n.mean_attitude, d.bounds_3dof), Fixed(100.0 * n.attitude_in_95, 1) + " %"});
  out << table.ToString();
  out << "  RMS error " << Fixed(1000.0 * d.rms_translation_error_m, 3) << " mm, "
      << Fixed(d.rms_rotation_error_deg, 4) << " deg; predicted by the stated covariances "
      << Fixed(1000.0 * d.rms_translation_sigma_m, 3) << " mm, "
      << Fixed(d.rms_rotation_sigma_deg, 4) << " deg (sqrt of the mean trace)\n";
  out << "  noise convention of the filter: p_meas = p_true + n_p, R_meas = R_true Exp(n_theta); "
         "bounds: two-sided 95 % of chi2(dof N) / N\n";
}

}  // namespace

void PrintVioReport(const VioRun& run, std::ostream& out) {
  out << "rover-eval vio: " << run.dataset_dir << "\n";
  out << "frames:       " << run.frames << " of " << run.dataset_frames
      << " stereo pairs; IMU samples fed " << run.imu_samples << "; wheel readings fed "
      << run.wheel_readings << "; VO latency " << General(run.vo_latency_s) << " s\n";
  out << "ground truth: "
      << (run.truth_source.empty() ? "none (figures against it are nan)" : run.truth_source)
      << "\n";
  for (const std::string& note : run.notes) out << note << "\n";
  for (std::size_t i = 0; i < run.issues.size() && i < kMaxIssueLines; ++i) {
    out << "dataset issue: " << run.issues[i] << "\n";
  }
  if (run.issues.size() > kMaxIssueLines) {
    out << "dataset issues: " << run.issues.size() - kMaxIssueLines << " more not listed\n";
  }
  if (run.filter_init_stamp) {
    out << "filter:       initialised "
        << Fixed((*run.filter_init_stamp - run.first_capture).ToSeconds(), 3)
        << " s after the first capture, " << run.filter_outputs << " outputs";
  } else {
    out << "filter:       never initialised (no standstill within its thresholds; see "
           "--filter-config)";
  }
  if (run.outputs_outside_frame_0 > 0) {
    out << ", " << run.outputs_outside_frame_0 << " outputs outside frame 0 (unexpected)";
  }
  out << "; wall time " << Fixed(run.wall_time_s, 1) << " s\n";

  PrintVoHealth(run, out);
  PrintVoTiming(run, out);
  PrintAccuracy(run, out);
  PrintRpe(run, out);
  PrintDeltaPoseNees(run, out);

  std::vector<double> total_ms;
  total_ms.reserve(run.vo_times.size());
  for (const vo::VoStageTimes& t : run.vo_times) total_ms.push_back(t.total_ms);
  const std::optional<ev::TrajectoryEvaluation>& fused = run.fused_evaluation;
  const double distance = fused ? fused->drift.distance_m : kNaN;
  const double final_m = run.fused_start.final_error_m;
  const double final_pct = distance > 0.0 ? 100.0 * final_m / distance : kNaN;
  out << "\n"
      << ResultLine({
             {"frames", std::to_string(run.frames)},
             {"distance_m", General(distance)},
             {"ate_rmse_m", General(fused ? fused->ate.position_m.rmse : kNaN)},
             {"final_err_m", General(final_m)},
             {"final_err_pct", General(final_pct)},
             {"rpe_trans_pct", General(run.vo_rpe.translation_pct)},
             {"rpe_rot_deg_per_m", General(run.vo_rpe.rotation_deg_per_m)},
             {"vo_ms_p50", General(Percentile(total_ms, 50.0))},
             {"vo_ms_p99", General(Percentile(total_ms, 99.0))},
         })
      << "\n";
}

int RunVio(const VioCommandOptions& options, std::ostream& out, std::ostream& err) {
  VioRun run;
  try {
    run = RunVioExperiment(options, err);
  } catch (const std::exception& e) {
    err << "rover-eval vio: " << e.what() << "\n";
    return kExitBadInput;
  }
  PrintVioReport(run, out);
  return run.filter_init_stamp ? kExitOk : kExitCheckFailed;
}

Subcommand AddVioCommand(CLI::App& app) {
  auto options = std::make_shared<VioCommandOptions>();
  CLI::App* cmd = app.add_subcommand(
      "vio",
      "Runs the stereo VO and the local reference filter offline, in lockstep, over an\n"
      "EuRoC-layout dataset (ours or a public one) and scores them against its ground truth:\n"
      "VO health and per-stage timing, ATE and final drift of the fused estimate, RPE of the VO\n"
      "alone, NEES of the VO's relative poses. For EuRoC MAV data pass\n"
      "--filter-config host/eval/config/euroc_mav.yaml (initialisation thresholds loose enough\n"
      "for a hovering MAV, no wheels, no zero-velocity updates).");
  cmd->add_option("--dataset", options->dataset_dir, "dataset folder (the one holding mav0/)")
      ->required()
      ->check(CLI::ExistingDirectory);
  cmd->add_option("--gt", options->truth_path,
                  "ground truth instead of mav0/state_groundtruth_estimate0/data.csv (EuRoC or "
                  "OpenVINS CSV)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--vo-config", options->vo_config_path,
                  "StereoOdometryOptions YAML (default: built-in options; the nominal frame "
                  "rate is the camera's unless the file sets checks.nominal_rate_hz)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--filter-config", options->filter_config_path,
                  "EskfOptions YAML applied on top of the defaults and the dataset's IMU noise "
                  "(e.g. host/eval/config/euroc_mav.yaml)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--vo-latency-s", options->vo_latency_s,
                  "delay from a frame's capture to the delivery of its VO result [s]")
      ->check(CLI::Range(0.0, 10.0))
      ->capture_default_str();
  cmd->add_flag(
      "--no-wheels", [options](std::int64_t) { options->wheels = false; },
      "do not feed the wheel speeds of mav0/can0/data.csv (simulator datasets)");
  cmd->add_option("--sim-config", options->sim_config_dir,
                  "folder with the simulator's rover_motion.yaml and wheels.yaml, for the wheel "
                  "geometry (default: the source tree's hil/config)")
      ->check(CLI::ExistingDirectory);
  cmd->add_option("--max-frames", options->max_frames, "process at most N stereo frames (0: all)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_option("--vo-log", options->vo_log_path,
                  "write one CSV row per VO frame (capture, status, quality, stage times)");
  cmd->add_option("--trajectory-out", options->trajectory_out_path,
                  "write the fused estimate (every filter output, frame 0) to this EuRoC CSV");
  cmd->footer(
      "The last line is\n"
      "  RESULT frames=... distance_m=... ate_rmse_m=... final_err_m=... final_err_pct=...\n"
      "         rpe_trans_pct=... rpe_rot_deg_per_m=... vo_ms_p50=... vo_ms_p99=...\n"
      "with \"nan\" for a field that cannot be computed:\n"
      "  frames             stereo pairs given to the VO\n"
      "  distance_m         ground-truth path length over the fused evaluation (filter\n"
      "                     initialisation to the last frame)\n"
      "  ate_rmse_m         RMS position error of the fused estimate (the filter output at\n"
      "                     each capture) after a 4-DoF (yaw + translation) alignment\n"
      "  final_err_m        position error of the fused estimate at the last frame, aligned\n"
      "                     (yaw + translation) at its first pose only\n"
      "  final_err_pct      final_err_m / distance_m * 100\n"
      "  rpe_trans_pct      VO alone (chains re-anchored after tracking losses): mean\n"
      "                     translation RPE of the 10 m segments [% of the segment], or of\n"
      "                     the longest shorter length that fits (the RPE table says which)\n"
      "  rpe_rot_deg_per_m  VO alone: mean rotation RPE of the same segments [deg/m]\n"
      "  vo_ms_p50          median VO processing time per frame [ms] (wall clock)\n"
      "  vo_ms_p99          99th percentile of the same [ms]\n"
      "Exit status: 0 ok, 1 the filter never initialised, 2 bad usage or unusable input.");

  Subcommand sub;
  sub.app = cmd;
  sub.run = [options]() {
    options->progress_in_place = isatty(STDERR_FILENO) != 0;
    return RunVio(*options, std::cout, std::cerr);
  };
  return sub;
}

}  // namespace rover::host::eval
