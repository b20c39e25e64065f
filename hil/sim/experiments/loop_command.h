#ifndef ROVER_HIL_SIM_EXPERIMENTS_LOOP_COMMAND_H_
#define ROVER_HIL_SIM_EXPERIMENTS_LOOP_COMMAND_H_

// `rover-sim loop`: the submap matcher (mapping/loop) on real submaps of a
// simulated drive, against ground truth. Along a scenario's route the
// stereo pairs are rendered and mapped by mapd's own per-image pipeline
// (firmware/mapd LocalMapper) into submaps of `submap_length_m` of driving,
// each in the gravity-aligned frame of its first pose (the true poses: the
// filter's drift within a submap is left out, the stereo is not). Every
// pair of non-successive submaps whose true obstacle boxes overlap by more
// than min_overlap_m2 is matched, 4D and 6D, with a prior that is the truth
// perturbed by seeded noise of the stated sigmas. Reported per seed and
// overall: suitable submaps, accepted and valid matches (within
// valid_translation_m and valid_rotation_deg of the truth), precision,
// median errors, covariance consistency, correspondence precision and
// timings. Only submaps that can take part in a pair are rendered.

#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/cli/subcommand.h"
#include "mapping/loop/submap_match_data.h"
#include "mapping/loop/submap_matcher.h"

namespace rover::sim::experiments {

struct LoopCommandOptions {
  std::string scenario = "mixed-300m";
  std::vector<uint64_t> seeds = {1, 2, 3};
  /// mapd's trigger distance.
  double submap_length_m = 7.0;
  /// One stereo pair mapped every this many seconds of the trajectory.
  double frame_period_s = 0.5;
  /// Pairs: true obstacle boxes overlapping by more than this.
  double min_overlap_m2 = 2.0;
  /// Prior = truth perturbed by N(0, sigma) per axis; its covariance says so.
  double prior_sigma_m = 0.5;
  double prior_sigma_yaw_deg = 3.0;
  /// A match is valid within these of the truth.
  double valid_translation_m = 0.2;
  double valid_rotation_deg = 1.0;
  /// 0: all pairs.
  int max_pairs_per_seed = 0;
  bool six_dof_baseline = true;
  /// Also run the 4D ICP from the truth and print what the validity checks
  /// see there (the pair's ceiling).
  bool truth_diagnostics = false;
  /// If set, built submaps (cloud and voxel space) are kept here and read
  /// back on the next run with the same scenario, seed and planning, so
  /// that matcher settings can be compared without rendering again.
  std::string cache_dir;
  mapping::SubmapMatchDataOptions data;
  mapping::SubmapMatcherOptions matcher;
};

/// One matcher's outcome on one pair.
struct LoopMatchOutcome {
  bool accepted = false;
  bool valid = false;
  std::string rejection;
  double translation_error_m = 0.0;
  /// truth - estimate, frame a.
  Eigen::Vector3d error_m = Eigen::Vector3d::Zero();
  double rotation_error_deg = 0.0;
  double yaw_error_deg = 0.0;
  /// Squared Mahalanobis distance of the error over x, y, z, yaw.
  double mahalanobis_sq = 0.0;
  double match_ms = 0.0;
  int correspondences = 0;
  /// Correspondences within 0.3 m of the truth.
  int true_correspondences = 0;
  int inliers = 0;
  double icp_rmse_m = 0.0;
  double overlap_ratio = 0.0;
  double obstacle_agreement = 0.0;
  /// Of the RANSAC winner, before the ICP.
  double initial_translation_error_m = 0.0;
  double initial_yaw_error_deg = 0.0;
  /// The ICP's s^2 H^-1: larger of the x, y sigmas, and yaw.
  double icp_sigma_xy_m = 0.0;
  double icp_sigma_yaw_deg = 0.0;
  bool inliers_on_a_line = false;
};

struct LoopPairRecord {
  uint64_t seed = 0;
  int a = 0;
  int b = 0;
  double overlap_m2 = 0.0;
  LoopMatchOutcome four;
  LoopMatchOutcome six;
};

struct LoopResult {
  int submaps = 0;
  int submaps_built = 0;
  int submaps_suitable = 0;
  /// Overlapping pairs, and those with both submaps suitable (matched).
  int pairs = 0;
  int pairs_matched = 0;
  std::vector<LoopPairRecord> records;
  double data_ms_median = 0.0;
};

/// Runs the evaluation over options.seeds, printing a line per pair and a
/// summary to `report`. Throws std::runtime_error for an unknown scenario or
/// no EGL renderer.
LoopResult EvaluateLoopClosures(const LoopCommandOptions& options, std::ostream& report);

/// The RESULT fields of `r`: "pairs=... valid_4d=... valid_6d=... ...".
std::string LoopResultFields(const LoopResult& r);

/// Runs it and prints, as the last line, RESULT <fields>. Errors go to
/// `err`; returns kExitBadInput for unusable input.
int RunLoop(const LoopCommandOptions& options, std::ostream& out, std::ostream& err);

/// Adds `rover-sim loop` to `app` (see subcommand.h).
cli::Subcommand AddLoopCommand(CLI::App& app);

}  // namespace rover::sim::experiments

#endif  // ROVER_HIL_SIM_EXPERIMENTS_LOOP_COMMAND_H_
