#ifndef ROVER_HOST_EVAL_ATE_COMMAND_H_
#define ROVER_HOST_EVAL_ATE_COMMAND_H_

// `rover-eval ate`: accuracy of an estimated trajectory against ground truth
// (ATE, RPE per segment length, drift, NEES when the estimate has covariances).

#include <ostream>
#include <string>

#include "core/cli/subcommand.h"
#include "estimator/eval/trajectory_evaluation.h"
#include "estimator/eval/trajectory_io.h"

namespace rover::host::eval {

using cli::kExitBadInput;
using cli::kExitOk;
using cli::Subcommand;

struct AteCommandOptions {
  std::string estimate_path;
  std::string truth_path;
  rover::eval::TrajectoryReadOptions estimate_read;  ///< Format and MCAP topics of the estimate.
  rover::eval::TrajectoryReadOptions truth_read;     ///< Format and MCAP topics of the truth.
  rover::eval::EvaluationOptions evaluation;         ///< Association, alignment, RPE lengths.
  /// If not empty, the aligned estimate is written here as TUM (for plotting).
  std::string aligned_output_path;
};

/// Runs the evaluation and prints the report to `out`: inputs, association
/// and alignment summary, the ATE table, the RPE table (one row per segment
/// length), drift, the NEES summary if the estimate has covariances, and as
/// the last line
///   RESULT poses=N distance_m=D ate_rmse_m=... ate_rot_rmse_deg=...
///          final_err_m=... final_err_pct=... mean_err_pct=...
///          rpe_trans_pct=... rpe_rot_deg_per_m=...
/// (RPE at the 10 m segment, or the nearest shorter length with results;
/// "nan" for anything that cannot be computed). Errors go to `err` as
/// "rover-eval ate: ..." and return kExitBadInput; success returns kExitOk.
int RunAte(const AteCommandOptions& options, std::ostream& out, std::ostream& err);

/// Adds `rover-eval ate` to `app` (see subcommand.h).
Subcommand AddAteCommand(CLI::App& app);

}  // namespace rover::host::eval

#endif  // ROVER_HOST_EVAL_ATE_COMMAND_H_
