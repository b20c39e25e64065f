#include "host/eval/vio_report.h"

#include <cmath>
#include <limits>
#include <vector>

#include "core/cli/report_format.h"
#include "core/stats/percentile.h"

namespace rover::host::eval {
namespace {

namespace ev = rover::eval;
namespace vo = rover::estimator::vo;
using cli::Fixed;
using cli::General;
using cli::ResultLine;
using cli::TextTable;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// Dataset issues listed in the report at most.
constexpr std::size_t kMaxIssueLines = 10;
// Below this spread of the fused positions the alignment yaw is fitted to noise.
constexpr double kMinAlignmentSpreadM = 0.5;

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
    table.AddRow({name, Fixed(stats::Percentile(v, 50.0), 2), Fixed(stats::Percentile(v, 99.0), 2),
                  Fixed(stats::Percentile(v, 100.0), 2)});
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
  for (std::size_t i = 0; i < kVioRpeSegmentsM.size(); ++i) {
    std::vector<std::string> cells = {General(kVioRpeSegmentsM[i])};
    if (kVioRpeSegmentsM[i] == run.vo_rpe.length_m) cells[0] += " *";
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
  const auto bounds = [](const rover::stats::ChiSquareInterval& b) {
    return "[" + Fixed(b.lower, 3) + ", " + Fixed(b.upper, 3) + "]";
  };
  const auto inside = [](double mean, const rover::stats::ChiSquareInterval& b) {
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
             {"vo_ms_p50", General(stats::Percentile(total_ms, 50.0))},
             {"vo_ms_p99", General(stats::Percentile(total_ms, 99.0))},
         })
      << "\n";
}

}  // namespace rover::host::eval
