#include "hil/sim/experiments/filter_command.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <exception>
#include <fstream>
#include <iostream>
#include <memory>
#include <mutex>
#include <numbers>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "core/cli/report_format.h"
#include "core/geometry/so3.h"
#include "core/geometry/yaw.h"
#include "estimator/eskf/eskf_health.h"
#include "estimator/eval/trajectory_evaluation.h"
#include "hil/sim/sensors/wheel_odometry_model.h"

namespace rover::sim::experiments {

using cli::Fixed;
using cli::General;
using cli::kExitBadInput;
using cli::kExitCheckFailed;
using cli::kExitOk;
using cli::ResultLine;
using cli::Subcommand;
using cli::TextTable;
namespace {

namespace ev = rover::eval;
using estimator::InputKind;
using estimator::RejectReason;

constexpr double kRadToDeg = 180.0 / std::numbers::pi;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// Rejection records printed per run at most.
constexpr int kMaxRejectLines = 20;

double Seconds(std::chrono::steady_clock::duration d) {
  return std::chrono::duration<double>(d).count();
}

// A gravity-aligned frame seen from the world: origin and yaw rotation.
struct Frame4 {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
};

// The true local frame defined at t (filter_run.h: true position and true yaw).
Frame4 TrueFrameAt(const sim::FilterFeed& feed, Time t) {
  const sim::TruthSample truth = feed.TruthAt(t);
  Frame4 f;
  f.origin = truth.p_world_body;
  f.R = Rz(YawOf(truth.q_world_body.toRotationMatrix()));
  return f;
}

double Pct(double error_m, double distance_m) {
  return distance_m > 0.0 ? 100.0 * error_m / distance_m : kNaN;
}

double Mean(const std::vector<double>& values) {
  if (values.empty()) return kNaN;
  double sum = 0.0;
  for (const double v : values) sum += v;
  return sum / static_cast<double>(values.size());
}

// One simulated run of `rover-sim filter`.
struct SimRun {
  uint64_t seed = 0;
  double simulated_s = 0.0;
  std::size_t inputs = 0;
  sim::FilterFeedCounts counts;
  double feed_wall_s = 0.0;
  sim::FilterRunResult result;  // without samples (dropped after the evaluation)
  std::optional<ev::TrajectoryEvaluation> evaluation;
  std::string evaluation_error;

  bool Initialised() const { return result.outputs > 0; }
  double FinalPct() const {
    return Initialised() ? Pct(result.final_global_position_error_m, result.distance_m) : kNaN;
  }
  double MeanPct() const {
    return Initialised() ? Pct(result.mean_global_position_error_m, result.distance_m) : kNaN;
  }
  double NeesPosition() const { return result.nees_samples > 0 ? result.mean_nees_position : kNaN; }
  double NeesAttitude() const { return result.nees_samples > 0 ? result.mean_nees_attitude : kNaN; }
  const ev::RpeSegmentResult* Rpe() const {
    return evaluation ? evaluation->rpe.Headline() : nullptr;
  }
  double AteRmse() const { return evaluation ? evaluation->ate.position_m.rmse : kNaN; }
  double RpeTransPct() const {
    const ev::RpeSegmentResult* r = Rpe();
    return r != nullptr ? r->translation_pct.mean : kNaN;
  }
  double RpeRotDegPerM() const {
    const ev::RpeSegmentResult* r = Rpe();
    return r != nullptr ? r->rotation_deg_per_m.mean : kNaN;
  }
};

void WriteCsv(const std::string& path, const sim::FilterFeed& feed, const sim::FilterRunResult& r) {
  std::ofstream out(path);
  out << "t_s,frame,dp_x,dp_y,dp_z,dth_x,dth_y,dth_z,dv_x,dv_y,dv_z,dpg_x,dpg_y,dpg_z,"
         "sp_x,sp_y,sp_z,sth_x,sth_y,sth_z,nees_p,nees_a,nees_valid\n";
  out.precision(9);
  for (const sim::FilterErrorSample& s : r.samples) {
    out << (s.stamp - feed.start()).ToSeconds() << ',' << s.frame_id;
    for (const Eigen::Vector3d* v : {&s.dp_local_m, &s.dtheta_rad, &s.dv_local_m_s, &s.dp_global_m,
                                     &s.sigma_p_m, &s.sigma_theta_rad}) {
      out << ',' << v->x() << ',' << v->y() << ',' << v->z();
    }
    out << ',' << s.nees_position << ',' << s.nees_attitude << ',' << s.nees_valid << '\n';
  }
  if (!out) throw std::runtime_error("cannot write " + path);
}

void PrintRejections(const sim::FilterFeed& feed, const sim::FilterRunResult& r,
                     std::ostream& out) {
  TextTable table({"input", "accepted", "rejected after init", "reasons"});
  for (int k = 0; k < estimator::kInputKindCount; ++k) {
    const auto kind = static_cast<InputKind>(k);
    std::string reasons;
    for (int c = 0; c < estimator::kRejectReasonCount; ++c) {
      const auto reason = static_cast<RejectReason>(c);
      const uint64_t n = r.health.Rejected(kind, reason);
      if (n == 0) continue;
      if (!reasons.empty()) reasons += ",";
      reasons += std::string(estimator::ToString(reason)) + ":" + std::to_string(n);
    }
    std::replace(reasons.begin(), reasons.end(), ' ', '_');
    table.AddRow({estimator::ToString(kind), std::to_string(r.health.Accepted(kind)),
                  std::to_string(r.RejectedAfterInit(kind)), reasons.empty() ? "-" : reasons});
  }
  out << table.ToString();
  int shown = 0;
  for (const estimator::RejectRecord& rec : r.rejects) {
    if (rec.reason == RejectReason::kNotInitialised) continue;
    if (shown++ == kMaxRejectLines) {
      out << "  ... (only the first " << kMaxRejectLines << " rejections are listed)\n";
      break;
    }
    out << "  rejected " << estimator::ToString(rec.kind) << " at "
        << Fixed((rec.stamp - feed.start()).ToSeconds(), 3)
        << " s: " << estimator::ToString(rec.reason);
    if (rec.reason == RejectReason::kGated) {
      out << " (d2 " << Fixed(rec.mahalanobis_sq, 1) << " > " << Fixed(rec.gate, 1) << ")";
    }
    out << "\n";
  }
}

void PrintAteRpe(const ev::TrajectoryEvaluation& e, std::ostream& out) {
  out << "\nAbsolute trajectory error (" << e.ate.position_m.count
      << " poses at 10 Hz, frame 0, no alignment)\n";
  TextTable ate({"", "rmse", "mean", "median", "std", "min", "max"});
  const auto row = [&](const char* name, const ev::ErrorStats& s, int decimals) {
    ate.AddRow({name, Fixed(s.rmse, decimals), Fixed(s.mean, decimals), Fixed(s.median, decimals),
                Fixed(s.std, decimals), Fixed(s.min, decimals), Fixed(s.max, decimals)});
  };
  row("position [m]", e.ate.position_m, 4);
  row("rotation [deg]", e.ate.rotation_deg, 3);
  out << ate.ToString();

  out << "\nRelative pose error per segment length (ground-truth distance)\n";
  TextTable rpe({"segment [m]", "segments", "trans mean [%]", "median", "rmse", "rot mean [deg/m]",
                 "median", "rmse"});
  const ev::RpeSegmentResult* headline = e.rpe.Headline();
  for (const ev::RpeSegmentResult& s : e.rpe.segments) {
    std::string length = General(s.length_m);
    if (&s == headline) length += " *";
    rpe.AddRow({length, std::to_string(s.translation_pct.count), Fixed(s.translation_pct.mean, 3),
                Fixed(s.translation_pct.median, 3), Fixed(s.translation_pct.rmse, 3),
                Fixed(s.rotation_deg_per_m.mean, 4), Fixed(s.rotation_deg_per_m.median, 4),
                Fixed(s.rotation_deg_per_m.rmse, 4)});
  }
  out << rpe.ToString();
  out << (headline != nullptr ? "  (* the segment quoted in RESULT)\n"
                              : "  (the trajectory is shorter than every segment length)\n");
}

void PrintRunDetails(const SimRun& run, const sim::FilterFeed* feed, std::ostream& out) {
  const sim::FilterRunResult& r = run.result;
  const sim::FilterFeedCounts& c = run.counts;
  out << "feed:      " << Fixed(run.simulated_s, 1) << " s simulated, " << run.inputs
      << " inputs (imu " << c.imu << ", wheels " << c.wheel_speeds << ", triggers "
      << c.clone_triggers << ", VO " << c.relative_poses << ", keyframes " << c.vo.keyframes
      << ", dropped " << c.vo.dropped << ", switches " << c.frame_switches << "), built in "
      << Fixed(run.feed_wall_s, 2) << " s\n";
  out << "filter:    " << r.outputs << " outputs, " << r.frame_switches
      << " switches, run + scoring " << Fixed(r.run_wall_time_s, 2)
      << " s, all finite: " << (r.all_finite ? "yes" : "NO")
      << ", frame ids consistent: " << (r.frame_ids_consistent ? "yes" : "NO") << "\n";
  if (!run.Initialised()) {
    out << "the filter never initialised\n";
    return;
  }
  const double d = r.distance_m;
  out << "distance:  " << Fixed(d, 2) << " m (horizontal, from initialisation)\n\n";
  TextTable errors({"position error", "final [m]", "final [%]", "mean [m]", "mean [%]", "max [m]"});
  errors.AddRow(
      {"global (frame-0 chain)", Fixed(r.final_global_position_error_m, 4),
       Fixed(Pct(r.final_global_position_error_m, d), 3), Fixed(r.mean_global_position_error_m, 4),
       Fixed(Pct(r.mean_global_position_error_m, d), 3), Fixed(r.max_global_position_error_m, 4)});
  errors.AddRow({"per frame", Fixed(r.final_position_error_m, 4),
                 Fixed(Pct(r.final_position_error_m, d), 3), Fixed(r.mean_position_error_m, 4),
                 Fixed(Pct(r.mean_position_error_m, d), 3), Fixed(r.max_position_error_m, 4)});
  out << errors.ToString();
  out << "attitude error: final " << Fixed(r.final_attitude_error_rad * kRadToDeg, 4)
      << " deg, max " << Fixed(r.max_attitude_error_rad * kRadToDeg, 4)
      << " deg; velocity error max " << Fixed(r.max_velocity_error_m_s, 4) << " m/s\n";
  out << "mean NEES: position " << Fixed(run.NeesPosition(), 3) << ", attitude "
      << Fixed(run.NeesAttitude(), 3) << " (3 if consistent; " << r.nees_samples << " samples)\n";
  out << "clones: created " << r.health.clones_created << ", marginalised "
      << r.health.clones_marginalised << ", evicted " << r.health.clones_evicted << "; ZUPTs "
      << r.health.zero_velocity_updates << "\n\n";
  if (feed != nullptr) PrintRejections(*feed, r, out);
  if (run.evaluation) {
    PrintAteRpe(*run.evaluation, out);
  } else {
    out << "\nATE/RPE: " << run.evaluation_error << "\n";
  }
}

}  // namespace

void SimSetup::Validate() const {
  (void)sim::VoNoiseModel::Preset(preset);  // throws for unknown names
  if (!(switch_distance_m >= 0.0)) {
    throw std::invalid_argument("switch distance must not be negative");
  }
  if (!(max_duration_s >= 0.0)) throw std::invalid_argument("duration must not be negative");
  if (!(drop_probability >= 0.0 && drop_probability < 1.0)) {
    throw std::invalid_argument("VO drop probability must be in [0, 1)");
  }
  if (!(vo_covariance_inflation > 0.0) || !std::isfinite(vo_covariance_inflation)) {
    throw std::invalid_argument("VO covariance inflation must be positive");
  }
}

std::string SimSetup::Describe() const {
  std::ostringstream s;
  s << "VO preset " << preset << ", wheels " << (wheels ? "on" : "off") << ", IMU "
    << (imu_white_only ? "white noise and biases only" : "full error model");
  if (switch_distance_m > 0.0) s << ", frame switch every " << General(switch_distance_m) << " m";
  if (max_duration_s > 0.0) s << ", first " << General(max_duration_s) << " s";
  if (drop_probability > 0.0) s << ", VO drops " << General(drop_probability);
  if (vo_covariance_inflation != 1.0) {
    s << ", filter VO covariance x " << General(vo_covariance_inflation);
  }
  return s.str();
}

sim::Scenario LoadSimScenario(const SimSetup& setup) {
  const std::string dir =
      setup.scenario_dir.empty() ? sim::DefaultScenarioDir() : setup.scenario_dir;
  const std::string config =
      setup.config_dir.empty() ? sim::DefaultSimConfigDir() : setup.config_dir;
  sim::Scenario scenario = sim::LoadScenario(sim::FindScenario(dir, setup.scenario), config);
  if (setup.imu_white_only) {
    for (sim::ImuTriadErrors* e : {&scenario.imu.gyro, &scenario.imu.accel}) {
      e->scale_factor_error.setZero();
      e->misalignment_rad.setZero();
    }
  }
  return scenario;
}

sim::FilterFeedOptions SimFeedOptions(const SimSetup& setup) {
  sim::FilterFeedOptions o;
  o.wheels_enabled = setup.wheels;
  o.max_duration_s = setup.max_duration_s;
  o.frame_switch_distance_m = setup.switch_distance_m;
  o.vo.noise = sim::VoNoiseModel::Preset(setup.preset);
  o.vo.drop_probability = setup.drop_probability;
  return o;
}

estimator::EskfOptions SimFilterOptions(const sim::FilterFeed& feed, const SimSetup& setup) {
  estimator::EskfOptions o = sim::EskfOptionsForFeed(feed);
  o.relative_pose.covariance_inflation = setup.vo_covariance_inflation;
  return o;
}

uint64_t RunSeed(uint64_t base_seed, int run) { return base_seed + static_cast<uint64_t>(run); }

std::string WheelSeedNote(const SimSetup& setup, const sim::Scenario& scenario) {
  if (!setup.wheels) return "";
  const sim::WheelOdometryModelOptions wheels =
      scenario.wheels_config.empty()
          ? sim::WheelOdometryModelOptions{}
          : sim::WheelOdometryModelOptions::LoadFile(scenario.wheels_config);
  std::string where = scenario.wheels_config.empty() ? "the default" : scenario.wheels_config;
  return "note: the wheel model's slip, velocity-noise and CAN-timing streams are seeded by " +
         where + " (seed " + std::to_string(wheels.seed) +
         ") and do not change with the run seed; only the terrain under the wheels does";
}

void RunInParallel(int runs, int jobs, const std::string& label,
                   const std::function<std::string(int)>& run, std::ostream& err) {
  if (runs <= 0) return;
  const int threads = std::clamp(jobs, 1, runs);
  std::atomic<int> next{0};
  std::atomic<bool> failed{false};
  std::mutex mutex;
  int done = 0;
  std::vector<std::exception_ptr> errors(static_cast<std::size_t>(runs));
  const auto start = std::chrono::steady_clock::now();
  const auto worker = [&] {
    for (;;) {
      if (failed.load()) return;
      const int i = next.fetch_add(1);
      if (i >= runs) return;
      const auto run_start = std::chrono::steady_clock::now();
      std::string summary;
      try {
        summary = run(i);
      } catch (...) {
        errors[static_cast<std::size_t>(i)] = std::current_exception();
        failed.store(true);
        summary = "failed";
      }
      const auto now = std::chrono::steady_clock::now();
      const std::lock_guard<std::mutex> lock(mutex);
      ++done;
      const double elapsed = Seconds(now - start);
      const double eta = elapsed / done * (runs - done);
      err << label << ": run " << done << "/" << runs << " done (run " << i + 1 << ", "
          << Fixed(Seconds(now - run_start), 1) << " s" << (summary.empty() ? "" : ", ") << summary
          << "), elapsed " << Fixed(elapsed, 0) << " s, ETA " << Fixed(eta, 0) << " s\n";
      err.flush();
    }
  };
  if (threads == 1) {
    worker();
  } else {
    std::vector<std::thread> pool;
    pool.reserve(static_cast<std::size_t>(threads));
    for (int t = 0; t < threads; ++t) pool.emplace_back(worker);
    for (std::thread& t : pool) t.join();
  }
  for (const std::exception_ptr& e : errors) {
    if (e) std::rethrow_exception(e);
  }
}

uint64_t RejectionsAfterInit(const sim::FilterRunResult& result) {
  uint64_t n = 0;
  for (int k = 0; k < estimator::kInputKindCount; ++k) {
    n += result.RejectedAfterInit(static_cast<InputKind>(k));
  }
  return n;
}

uint64_t GatedRejections(const sim::FilterRunResult& result) {
  uint64_t n = 0;
  for (int k = 0; k < estimator::kInputKindCount; ++k) {
    n += result.health.Rejected(static_cast<InputKind>(k), RejectReason::kGated);
  }
  return n;
}

SimTrajectories BuildSimTrajectories(const sim::FilterFeed& feed,
                                     const sim::FilterRunResult& result, double step_s) {
  SimTrajectories t;
  t.estimate.set_source("filter estimate (frame 0)");
  t.truth.set_source("simulator ground truth (true frame 0)");
  if (result.outputs == 0 || result.samples.empty()) return t;

  // True frames and the filter's chain T_L0_Lk, per frame id.
  std::vector<Frame4> true_frames = {TrueFrameAt(feed, result.init_stamp)};
  std::vector<Frame4> chain = {Frame4{}};
  for (const estimator::FrameSwitchRecord& rec : result.switches) {
    true_frames.push_back(TrueFrameAt(feed, rec.stamp));
    Frame4 next = chain.back();
    next.origin += chain.back().R * rec.p_old_new;
    next.R = chain.back().R * Rz(rec.yaw_old_new_rad);
    chain.push_back(next);
  }
  const Frame4& f0 = true_frames.front();
  const Duration step = Duration::FromSeconds(step_s);
  Time next = feed.start();
  for (const sim::FilterErrorSample& s : result.samples) {
    if (s.stamp < next) continue;
    while (next <= s.stamp) next += step;
    const std::size_t k = std::min<std::size_t>(s.frame_id, true_frames.size() - 1);
    const Frame4& fk = true_frames[k];
    const Frame4& ck = chain[k];
    const sim::TruthSample truth = feed.TruthAt(s.stamp);
    const Eigen::Matrix3d R_w = truth.q_world_body.toRotationMatrix();
    // The estimate in its frame k, from the errors (p_true - p, Log(R^T R_true)).
    const Eigen::Vector3d p_true_k = fk.R.transpose() * (truth.p_world_body - fk.origin);
    const Eigen::Matrix3d R_true_k = fk.R.transpose() * R_w;
    const Eigen::Vector3d p_est_k = p_true_k - s.dp_local_m;
    const Eigen::Matrix3d R_est_k = R_true_k * ExpSO3(-s.dtheta_rad);

    ev::PoseSample est;
    est.stamp = s.stamp;
    est.p_world_body = ck.origin + ck.R * p_est_k;
    est.q_world_body = Eigen::Quaterniond(ck.R * R_est_k).normalized();
    t.estimate.Append(est);

    ev::PoseSample tru;
    tru.stamp = s.stamp;
    tru.p_world_body = f0.R.transpose() * (truth.p_world_body - f0.origin);
    tru.q_world_body = Eigen::Quaterniond(f0.R.transpose() * R_w).normalized();
    tru.v_world_body_m_s = f0.R.transpose() * truth.v_world_m_s;
    t.truth.Append(tru);
  }
  return t;
}

int RunFilterCommand(const FilterCommandOptions& options, std::ostream& out, std::ostream& err) {
  const auto wall_start = std::chrono::steady_clock::now();
  std::vector<SimRun> runs;
  sim::Scenario scenario;
  std::unique_ptr<sim::FilterFeed> first_feed;  // kept for the details of a single run
  try {
    options.setup.Validate();
    if (options.runs < 1) throw std::invalid_argument("--runs must be at least 1");
    if (options.jobs < 1) throw std::invalid_argument("--jobs must be at least 1");
    for (const double s : options.segments_m) {
      if (!(s > 0.0)) throw std::invalid_argument("RPE segment lengths must be positive");
    }
    scenario = LoadSimScenario(options.setup);
    runs.resize(static_cast<std::size_t>(options.runs));
    ev::EvaluationOptions evaluation;
    evaluation.alignment.method = ev::AlignmentMethod::kNone;
    evaluation.association.max_gap = Duration::Seconds(1);
    evaluation.rpe.segment_lengths_m = options.segments_m;

    RunInParallel(
        options.runs, options.jobs, "rover-sim filter",
        [&](int i) {
          SimRun& run = runs[static_cast<std::size_t>(i)];
          run.seed = RunSeed(options.seed, i);
          const auto t0 = std::chrono::steady_clock::now();
          auto feed =
              std::make_unique<sim::FilterFeed>(scenario, run.seed, SimFeedOptions(options.setup));
          run.feed_wall_s = Seconds(std::chrono::steady_clock::now() - t0);
          run.simulated_s = (feed->end() - feed->start()).ToSeconds();
          run.inputs = feed->inputs().size();
          run.counts = feed->counts();
          run.result = sim::RunFilter(*feed, SimFilterOptions(*feed, options.setup));
          if (i == 0 && !options.csv_path.empty()) WriteCsv(options.csv_path, *feed, run.result);
          const SimTrajectories traj = BuildSimTrajectories(*feed, run.result);
          try {
            run.evaluation = ev::EvaluateTrajectory(traj.estimate, traj.truth, evaluation);
          } catch (const std::exception& e) {
            run.evaluation_error = e.what();
          }
          run.result.samples.clear();
          run.result.samples.shrink_to_fit();
          if (options.runs == 1) first_feed = std::move(feed);
          return "seed " + std::to_string(run.seed) + ", final error " + Fixed(run.FinalPct(), 3) +
                 " % of distance";
        },
        err);
  } catch (const std::exception& e) {
    err << "rover-sim filter: " << e.what() << "\n";
    return kExitBadInput;
  }

  out << "rover-sim filter: scenario " << scenario.name << ", " << options.runs
      << (options.runs == 1 ? " run" : " runs") << ", seed"
      << (options.runs == 1 ? " " + std::to_string(options.seed)
                            : "s " + std::to_string(options.seed) + ".." +
                                  std::to_string(RunSeed(options.seed, options.runs - 1)))
      << " (run i uses seed S + i)\n";
  out << "setup: " << options.setup.Describe() << "\n";
  const std::string note = WheelSeedNote(options.setup, scenario);
  if (!note.empty()) out << note << "\n";
  out << "estimate: the filter's pose chained through its frame switches into frame 0 (the true "
         "pose at initialisation), compared without alignment\n\n";

  bool all_initialised = true;
  for (const SimRun& r : runs) all_initialised = all_initialised && r.Initialised();

  if (options.runs == 1) {
    PrintRunDetails(runs.front(), first_feed.get(), out);
  } else {
    TextTable table({"run", "seed", "distance [m]", "final [m]", "final [%]", "mean [%]", "max [m]",
                     "att final [deg]", "ATE [m]", "RPE [%]", "RPE [deg/m]", "NEES pos", "NEES att",
                     "rejections", "gated"});
    for (std::size_t i = 0; i < runs.size(); ++i) {
      const SimRun& r = runs[i];
      table.AddRow({std::to_string(i + 1), std::to_string(r.seed), Fixed(r.result.distance_m, 2),
                    Fixed(r.result.final_global_position_error_m, 4), Fixed(r.FinalPct(), 3),
                    Fixed(r.MeanPct(), 3), Fixed(r.result.max_global_position_error_m, 4),
                    Fixed(r.result.final_attitude_error_rad * kRadToDeg, 3), Fixed(r.AteRmse(), 4),
                    Fixed(r.RpeTransPct(), 3), Fixed(r.RpeRotDegPerM(), 4),
                    Fixed(r.NeesPosition(), 3), Fixed(r.NeesAttitude(), 3),
                    std::to_string(RejectionsAfterInit(r.result)),
                    std::to_string(GatedRejections(r.result))});
    }
    out << table.ToString();
  }

  const auto mean_of = [&](double (*f)(const SimRun&)) {
    std::vector<double> v;
    for (const SimRun& r : runs) v.push_back(f(r));
    return Mean(v);
  };
  const double distance =
      mean_of([](const SimRun& r) { return r.Initialised() ? r.result.distance_m : kNaN; });
  const double final_m = mean_of([](const SimRun& r) {
    return r.Initialised() ? r.result.final_global_position_error_m : kNaN;
  });
  const double final_pct = mean_of([](const SimRun& r) { return r.FinalPct(); });
  const double mean_pct = mean_of([](const SimRun& r) { return r.MeanPct(); });
  const double ate = mean_of([](const SimRun& r) { return r.AteRmse(); });
  const double rpe_trans = mean_of([](const SimRun& r) { return r.RpeTransPct(); });
  const double rpe_rot = mean_of([](const SimRun& r) { return r.RpeRotDegPerM(); });
  const double nees_p = mean_of([](const SimRun& r) { return r.NeesPosition(); });
  const double nees_a = mean_of([](const SimRun& r) { return r.NeesAttitude(); });

  if (options.runs > 1) {
    out << "\nMean over " << options.runs << " runs: distance " << Fixed(distance, 2)
        << " m, final error " << Fixed(final_m, 4) << " m (" << Fixed(final_pct, 3)
        << " %), mean error " << Fixed(mean_pct, 3) << " %, ATE " << Fixed(ate, 4) << " m, RPE "
        << Fixed(rpe_trans, 3) << " % / " << Fixed(rpe_rot, 4) << " deg/m, NEES position "
        << Fixed(nees_p, 3) << ", attitude " << Fixed(nees_a, 3) << "\n";
  }
  if (!all_initialised) out << "\nwarning: the filter never initialised in some runs\n";
  out << "wall time: " << Fixed(Seconds(std::chrono::steady_clock::now() - wall_start), 1) << " s ("
      << options.jobs << (options.jobs == 1 ? " job" : " jobs") << ")\n";
  out << "\n"
      << ResultLine({
             {"scenario", scenario.name},
             {"runs", std::to_string(options.runs)},
             {"distance_m", General(distance)},
             {"final_err_m", General(final_m)},
             {"final_err_pct", General(final_pct)},
             {"mean_err_pct", General(mean_pct)},
             {"ate_rmse_m", General(ate)},
             {"rpe_trans_pct", General(rpe_trans)},
             {"rpe_rot_deg_per_m", General(rpe_rot)},
             {"nees_pos_mean", General(nees_p)},
             {"nees_att_mean", General(nees_a)},
         })
      << "\n";
  return all_initialised ? kExitOk : kExitCheckFailed;
}

void AddSimSetupOptions(CLI::App* cmd, SimSetup* setup, std::string* wheels, int* jobs) {
  cmd->add_option("--jobs", *jobs, "runs in parallel threads (results do not depend on it)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--preset", setup->preset, "synthetic VO noise preset")
      ->check(CLI::IsMember({"ideal-consistent", "realistic"}))
      ->capture_default_str();
  cmd->add_option("--wheels", *wheels, "wheel speeds into the filter")
      ->check(CLI::IsMember({"on", "off"}))
      ->capture_default_str();
  cmd->add_option("--switch-distance-m", setup->switch_distance_m,
                  "frame switch every D metres driven (0: never)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_option("--duration-s", setup->max_duration_s, "simulated seconds (0: whole route)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_flag("--imu-white-only", setup->imu_white_only,
                "simulate the IMU without scale-factor and misalignment errors (the filter's "
                "own error model)");
  cmd->add_option("--vo-cov-inflation", setup->vo_covariance_inflation,
                  "scale the VO covariance the filter assumes (1: as stated; <1 makes the "
                  "filter overconfident)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
}

Subcommand AddFilterCommand(CLI::App& app) {
  struct State {
    FilterCommandOptions options;
    std::string wheels = "on";
  };
  auto state = std::make_shared<State>();
  FilterCommandOptions& o = state->options;

  CLI::App* cmd = app.add_subcommand(
      "filter",
      "Runs the local reference filter alone on a simulated scenario (IMU, wheel speeds from\n"
      "the CAN bus, synthetic keyframe VO) and scores it against the ground truth: distance,\n"
      "final and mean position error (m and % of distance), ATE, RPE, attitude error, NEES,\n"
      "rejections. Run i uses seed S + i; with --runs > 1 the RESULT line holds the means.");
  cmd->add_option("--scenario", o.setup.scenario,
                  "scenario name (short, loop-100m, mixed-300m, ...)")
      ->capture_default_str();
  cmd->add_option("--seed", o.seed, "seed of the first run (world, IMU and VO streams)")
      ->capture_default_str();
  cmd->add_option("--runs", o.runs, "number of runs (seeds S, S+1, ...)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  AddSimSetupOptions(cmd, &o.setup, &state->wheels, &o.jobs);
  cmd->add_option("--drop", o.setup.drop_probability, "VO frame drop probability")
      ->check(CLI::Range(0.0, 0.99))
      ->capture_default_str();
  cmd->add_option("--segments", o.segments_m, "RPE segment lengths [m], comma-separated")
      ->delimiter(',')
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--csv", o.csv_path,
                  "write every filter output's errors and sigmas of the first run to this file");

  Subcommand sub;
  sub.app = cmd;
  sub.run = [state]() {
    state->options.setup.wheels = state->wheels == "on";
    return RunFilterCommand(state->options, std::cout, std::cerr);
  };
  return sub;
}

}  // namespace rover::sim::experiments
