#include "host/eval/vio_command.h"

#include <unistd.h>

#include <iostream>
#include <memory>

#include "host/eval/vio_report.h"

namespace rover::host::eval {

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
                  "EskfOptions YAML whose keys override the options from the dataset's "
                  "calibration, as roverd's estimator_config does "
                  "(e.g. host/eval/config/euroc_mav.yaml)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--vo-latency-s", options->vo_latency_s,
                  "delay from a frame's capture to the delivery of its VO result [s]")
      ->check(CLI::Range(0.0, 10.0))
      ->capture_default_str();
  cmd->add_flag(
      "--no-wheels", [options](std::int64_t) { options->wheels = false; },
      "do not feed the wheel speeds of mav0/can0/data.csv (fed by default when the dataset\n"
      "calibrates the wheels in mav0/can0/sensor.yaml, as `rover-sim generate` writes it)");
  cmd->add_option("--max-frames", options->max_frames, "process at most N stereo frames (0: all)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_option("--vo-log", options->vo_log_path,
                  "write one CSV row per VO frame (capture, status, quality, stage times)");
  cmd->add_option("--trajectory-out", options->trajectory_out_path,
                  "write the fused estimate (every filter output, frame 0) to this EuRoC CSV");
  cmd->add_option("--vo-trajectory-out", options->vo_trajectory_out_path,
                  "write the VO's chained poses alone (odometry frame: the body at the first\n"
                  "keyframe) to this EuRoC CSV");
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
