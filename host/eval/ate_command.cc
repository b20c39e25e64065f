#include "host/eval/ate_command.h"

#include <cmath>
#include <memory>
#include <numbers>

#include "core/cli/report_format.h"
#include "core/geometry/so3.h"
#include "core/geometry/yaw.h"
#include "core/stats/chi_square.h"
#include "estimator/eval/eval_error.h"
#include "estimator/eval/tum_trajectory.h"

namespace rover::host::eval {

using cli::Fixed;
using cli::General;
using cli::kExitBadInput;
using cli::kExitOk;
using cli::ResultLine;
using cli::Subcommand;
using cli::TextTable;
namespace {

namespace ev = rover::eval;

constexpr double kRadToDeg = 180.0 / std::numbers::pi;
// Below this spread of the estimate positions the report warns that the
// alignment rotation is fitted to noise.
constexpr double kMinAlignmentSpreadM = 0.5;

std::string Counted(std::size_t n, const char* what) { return std::to_string(n) + " " + what; }

void PrintAlignment(const ev::Alignment& a, std::ostream& out) {
  out << "alignment:    " << ev::ToString(a.method);
  if (a.method == ev::AlignmentMethod::kNone) {
    out << " (identity)\n";
    return;
  }
  const Eigen::Vector3d t = a.T_truth_estimate.translation();
  const Eigen::Vector3d rotation_vector = LogSO3(Eigen::Matrix3d(a.T_truth_estimate.linear()));
  out << " from " << a.poses_used << " poses: ";
  if (a.method == ev::AlignmentMethod::kFourDof) {
    out << "yaw " << Fixed(YawOf(a.T_truth_estimate.linear()) * kRadToDeg, 3) << " deg";
  } else {
    out << "rotation " << Fixed(rotation_vector.norm() * kRadToDeg, 3) << " deg";
  }
  out << ", translation (" << Fixed(t.x(), 4) << ", " << Fixed(t.y(), 4) << ", " << Fixed(t.z(), 4)
      << ") m";
  if (a.method == ev::AlignmentMethod::kSim3) out << ", scale " << Fixed(a.scale, 6);
  out << "\n";
  if (a.spread_m < kMinAlignmentSpreadM) {
    out << "warning:      the aligned positions spread only " << Fixed(a.spread_m, 3)
        << " m around their centroid; the alignment rotation is poorly determined\n";
  }
}

void PrintAte(const ev::AteResult& ate, std::ostream& out) {
  out << "\nAbsolute trajectory error (" << ate.position_m.count << " poses)\n";
  TextTable table({"", "rmse", "mean", "median", "std", "min", "max"});
  const auto row = [&](const char* name, const ev::ErrorStats& s, int decimals) {
    table.AddRow({name, Fixed(s.rmse, decimals), Fixed(s.mean, decimals), Fixed(s.median, decimals),
                  Fixed(s.std, decimals), Fixed(s.min, decimals), Fixed(s.max, decimals)});
  };
  row("position [m]", ate.position_m, 4);
  row("rotation [deg]", ate.rotation_deg, 3);
  out << table.ToString();
}

void PrintRpe(const ev::RpeResult& rpe, std::ostream& out) {
  out << "\nRelative pose error per segment length (ground-truth distance)\n";
  TextTable table({"segment [m]", "segments", "trans mean [%]", "median", "rmse",
                   "rot mean [deg/m]", "median", "rmse"});
  const ev::RpeSegmentResult* headline = rpe.Headline();
  for (const ev::RpeSegmentResult& s : rpe.segments) {
    std::string length = General(s.length_m);
    if (&s == headline) length += " *";
    table.AddRow({length, std::to_string(s.translation_pct.count), Fixed(s.translation_pct.mean, 3),
                  Fixed(s.translation_pct.median, 3), Fixed(s.translation_pct.rmse, 3),
                  Fixed(s.rotation_deg_per_m.mean, 4), Fixed(s.rotation_deg_per_m.median, 4),
                  Fixed(s.rotation_deg_per_m.rmse, 4)});
  }
  out << table.ToString();
  out << (headline != nullptr ? "  (* the segment quoted in RESULT)\n"
                              : "  (the trajectory is shorter than every segment length)\n");
}

void PrintNees(const ev::NeesResult& nees, std::ostream& out) {
  out << "\nNEES (" << nees.samples.size() << " poses with covariance";
  if (nees.without_covariance > 0) out << ", " << nees.without_covariance << " without";
  if (nees.singular > 0) out << ", " << nees.singular << " not positive definite";
  out << ")\n";
  const double lower = rover::stats::Chi2Quantile(3, 0.025),
               upper = rover::stats::Chi2Quantile(3, 0.975);
  TextTable table({"", "dof", "mean", "expected", "in 95% interval"});
  table.AddRow({"position", "3", Fixed(nees.mean_position, 3), "3",
                Fixed(100.0 * nees.position_in_95, 1) + " %"});
  table.AddRow({"attitude", "3", Fixed(nees.mean_attitude, 3), "3",
                Fixed(100.0 * nees.attitude_in_95, 1) + " %"});
  table.AddRow({"pose", "6", Fixed(nees.mean_pose, 3), "6", "-"});
  out << table.ToString();
  out << "  (95% interval of one 3-dof sample: [" << Fixed(lower, 3) << ", " << Fixed(upper, 3)
      << "]; the mean of a consistent filter is near the dof)\n";
}

ev::Trajectory Read(const std::string& role, const std::string& path,
                    const ev::TrajectoryReadOptions& options, std::ostream& out) {
  ev::TrajectoryFormat format = ev::TrajectoryFormat::kAuto;
  ev::Trajectory t = ev::ReadTrajectory(path, options, &format);
  out << role << path << " (" << ev::ToString(format) << ", " << t.size() << " poses, "
      << Fixed(t.Span().ToSeconds(), 3) << " s" << (t.HasCovariance() ? ", with covariance" : "")
      << ")\n";
  return t;
}

}  // namespace

int RunAte(const AteCommandOptions& options, std::ostream& out, std::ostream& err) {
  try {
    const ev::Trajectory estimate =
        Read("estimate:     ", options.estimate_path, options.estimate_read, out);
    const ev::Trajectory truth =
        Read("ground truth: ", options.truth_path, options.truth_read, out);
    const ev::TrajectoryEvaluation r = ev::EvaluateTrajectory(estimate, truth, options.evaluation);

    out << "associated:   " << r.aligned.size() << " of " << r.estimate_poses << " poses ("
        << Counted(r.skipped_outside, "outside the ground-truth span") << ", "
        << Counted(r.skipped_gap, "in ground-truth gaps > ")
        << General(options.evaluation.association.max_gap.ToSeconds()) << " s), time offset "
        << General(options.evaluation.association.time_offset.ToSeconds()) << " s\n";
    PrintAlignment(r.alignment, out);
    out << "distance:     " << Fixed(r.drift.distance_m, 3) << " m travelled (ground truth)\n";

    PrintAte(r.ate, out);
    PrintRpe(r.rpe, out);
    out << "\nDrift\n";
    out << "  final position error  " << Fixed(r.drift.final_error_m, 4) << " m  ("
        << Fixed(r.drift.final_error_pct, 3) << " % of distance)\n";
    out << "  mean position error   " << Fixed(r.drift.mean_error_m, 4) << " m  ("
        << Fixed(r.drift.mean_error_pct, 3) << " % of distance)\n";
    if (r.nees) PrintNees(*r.nees, out);

    if (!options.aligned_output_path.empty()) {
      ev::Trajectory aligned;
      for (const ev::AssociatedPose& p : r.aligned) {
        ev::PoseSample s;
        s.stamp = p.stamp;
        s.p_world_body = p.T_world_body_estimate.translation();
        s.q_world_body = Eigen::Quaterniond(p.T_world_body_estimate.linear()).normalized();
        aligned.Append(s);
      }
      ev::WriteTumTrajectory(aligned, options.aligned_output_path);
      out << "\naligned estimate written to " << options.aligned_output_path << " (TUM)\n";
    }

    const ev::RpeSegmentResult* rpe = r.rpe.Headline();
    const double nan = std::nan("");
    out << "\n"
        << ResultLine({
               {"poses", std::to_string(r.aligned.size())},
               {"distance_m", General(r.drift.distance_m)},
               {"ate_rmse_m", General(r.ate.position_m.rmse)},
               {"ate_rot_rmse_deg", General(r.ate.rotation_deg.rmse)},
               {"final_err_m", General(r.drift.final_error_m)},
               {"final_err_pct", General(r.drift.final_error_pct)},
               {"mean_err_pct", General(r.drift.mean_error_pct)},
               {"rpe_trans_pct", General(rpe != nullptr ? rpe->translation_pct.mean : nan)},
               {"rpe_rot_deg_per_m", General(rpe != nullptr ? rpe->rotation_deg_per_m.mean : nan)},
           })
        << "\n";
    return kExitOk;
  } catch (const ev::EvalError& e) {
    err << "rover-eval ate: " << e.what() << "\n";
    return kExitBadInput;
  } catch (const std::exception& e) {
    err << "rover-eval ate: unexpected error: " << e.what() << "\n";
    return kExitBadInput;
  }
}

Subcommand AddAteCommand(CLI::App& app) {
  struct State {
    AteCommandOptions options;
    std::string estimate_format = "auto";
    std::string truth_format = "auto";
    std::string align = "se3";
    std::vector<double> segments = {1, 5, 10, 20, 50};
    double max_gap_s = 0.02;
    double offset_s = 0.0;
    double align_first_s = 0.0;
    std::string topic;
    std::string switch_topic;
    std::string gt_topic;
  };
  auto state = std::make_shared<State>();
  const std::vector<std::string> formats = {"auto", "tum", "euroc", "openvins", "mcap"};

  CLI::App* cmd = app.add_subcommand(
      "ate",
      "Accuracy of an estimate against ground truth: ATE, RPE per segment length, drift, NEES.\n"
      "Both trajectories are read (TUM, EuRoC CSV, OpenVINS CSV or a rover flight log), the\n"
      "ground truth is interpolated at each estimate stamp, the estimate is aligned to it, and\n"
      "the last line of the report is a machine-readable RESULT line.");
  cmd->add_option("--est", state->options.estimate_path, "estimated trajectory file")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--gt", state->options.truth_path, "ground-truth trajectory file")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--align", state->align,
                  "alignment: se3 (rotation+translation), sim3 (+scale), 4dof (yaw+translation, "
                  "right for VIO), none")
      ->check(CLI::IsMember({"se3", "sim3", "4dof", "none"}))
      ->capture_default_str();
  cmd->add_option("--align-first-poses", state->options.evaluation.alignment.first_poses,
                  "align on the first N associated poses only (0: all)")
      ->capture_default_str();
  cmd->add_option("--align-first-s", state->align_first_s,
                  "align on the poses within this many seconds of the first (0: all)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_option("--segments", state->segments,
                  "RPE segment lengths in metres of travelled distance, comma-separated")
      ->delimiter(',')
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--max-gap-s", state->max_gap_s,
                  "largest spacing of the ground-truth samples to interpolate across [s]")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option(
         "--offset-s", state->offset_s,
         "time offset: the estimate at t is compared with the ground truth at t + offset [s]")
      ->capture_default_str();
  cmd->add_option("--est-format", state->estimate_format, "format of --est")
      ->check(CLI::IsMember(formats))
      ->capture_default_str();
  cmd->add_option("--gt-format", state->truth_format, "format of --gt")
      ->check(CLI::IsMember(formats))
      ->capture_default_str();
  cmd->add_option("--topic", state->topic,
                  "MCAP inputs: topic of the poses (nav_msgs/Odometry or "
                  "geometry_msgs/PoseWithCovarianceStamped; default /estimator/odometry)");
  cmd->add_option("--gt-topic", state->gt_topic,
                  "MCAP ground truth: topic of its poses, if it differs from --topic");
  cmd->add_option("--switch-topic", state->switch_topic,
                  "MCAP inputs: topic of the frame switches (default /estimator/frame_switch)");
  cmd->add_option("--save-aligned", state->options.aligned_output_path,
                  "write the aligned estimate to this file (TUM)");

  Subcommand sub;
  sub.app = cmd;
  sub.run = [state]() {
    AteCommandOptions& o = state->options;
    o.estimate_read.format = *ev::ParseTrajectoryFormat(state->estimate_format);
    o.truth_read.format = *ev::ParseTrajectoryFormat(state->truth_format);
    for (ev::TrajectoryReadOptions* read : {&o.estimate_read, &o.truth_read}) {
      if (!state->topic.empty()) read->mcap.topic = state->topic;
      if (!state->switch_topic.empty()) read->mcap.frame_switch_topic = state->switch_topic;
    }
    if (!state->gt_topic.empty()) o.truth_read.mcap.topic = state->gt_topic;
    o.evaluation.alignment.method = *ev::ParseAlignmentMethod(state->align);
    o.evaluation.alignment.first_duration = Duration::FromSeconds(state->align_first_s);
    o.evaluation.rpe.segment_lengths_m = state->segments;
    o.evaluation.association.max_gap = Duration::FromSeconds(state->max_gap_s);
    o.evaluation.association.time_offset = Duration::FromSeconds(state->offset_s);
    return RunAte(o, std::cout, std::cerr);
  };
  return sub;
}

}  // namespace rover::host::eval
