#ifndef ROVER_HIL_SIM_EXPERIMENTS_NEES_COMMAND_H_
#define ROVER_HIL_SIM_EXPERIMENTS_NEES_COMMAND_H_

// `rover-sim nees`: Monte Carlo consistency of the local reference filter on
// the simulator. N seeded runs of a scenario, the filter
// alone; the synthetic VO's relative poses are ground truth perturbed by
// exactly their stated covariance.
//
// Seeds: run i (0-based) uses seed S + i for the world, every IMU stream and
// the VO's noise, drops and latency (see sim_command.h); the wheel model's
// streams keep the seed of the scenario's wheels file, which the report says
// when wheel speeds are used.
//
// Statistics.
//  * Per run: the time average of the position and attitude NEES over the
//    outputs RunFilter marks valid (every filter output, ~400 Hz, after the
//    first nees_skip_s).
//  * Monte Carlo average: the mean of those time averages over the N runs,
//    checked against AverageNeesBounds(3, N, confidence) = the two-sided
//    interval of chi2(3N)/N, the distribution of the average of N independent
//    3-dof NEES samples of a consistent filter AT ONE TIME STEP. A run's time
//    average has the same mean (3) but a variance between 6/T_eff and 6 (it
//    averages correlated samples), so the run average of time averages is
//    never more spread out than chi2(3N)/N: for it these bounds are
//    conservative (a consistent filter is inside with at least the stated
//    confidence; a slightly inconsistent one is detected less often than the
//    confidence suggests). In practice the errors of this filter (position and
//    yaw are unobservable random walks) are correlated over a whole run, so
//    the variance is close to 6 and the bounds are nearly exact.
//  * Per time step (the exact form of the test): the runs of one scenario
//    share one time grid, so at every grid step (step_s apart from the feed
//    start; each run's output nearest to the grid time, within half an IMU
//    period, if its NEES is valid) the NEES is averaged over the runs and
//    compared with the same bounds. The report gives the fraction of the
//    steps (valid in every run) inside the bounds, expected to be about the
//    confidence for a consistent filter. Neighbouring steps are strongly
//    correlated, so that fraction scatters widely from one experiment to the
//    next; it is reported, not checked.
//
// The check (exit status kExitCheckFailed if it fails): both Monte Carlo
// averages inside the bounds.

#include <cstdint>
#include <ostream>
#include <vector>

#include "core/cli/subcommand.h"
#include "hil/sim/experiments/filter_command.h"

namespace rover::sim::experiments {

using cli::kExitBadInput;
using cli::kExitCheckFailed;
using cli::kExitOk;
using cli::Subcommand;

struct NeesCommandOptions {
  /// The default is the setup whose simulated sensors the filter models best:
  /// the ideal-consistent VO preset (noise drawn from the stated covariance,
  /// small enough for the linearisation to hold) and no wheel speeds (the
  /// simulator's wheels slip by a terrain- and tilt-dependent ratio with
  /// correlated noise that the filter's wheel model only approximates, and
  /// their noise seed does not vary between runs).
  SimSetup setup = [] {
    SimSetup s;
    s.scenario = "short";
    s.preset = "ideal-consistent";
    s.wheels = false;
    return s;
  }();
  uint64_t seed = 1;
  int runs = 25;
  int jobs = 1;
  double confidence = 0.95;
  /// Grid of the per-time-step comparison [s].
  double grid_step_s = 0.1;
  /// Excluded from the NEES after initialisation and each frame switch [s].
  double nees_skip_s = 1.0;
};

/// One run of the experiment.
struct NeesRun {
  uint64_t seed = 0;
  double distance_m = 0.0;
  double final_error_m = 0.0;  ///< global (frame-0 chain) position error at the end
  double nees_position = 0.0;  ///< time average (NaN without valid samples)
  double nees_attitude = 0.0;
  uint64_t nees_samples = 0;
  uint64_t rejections = 0;  ///< after initialisation, every input kind
  uint64_t gated = 0;
  double wall_time_s = 0.0;
  /// NEES at grid step k (NaN where the run has no valid output there).
  std::vector<double> grid_position;
  std::vector<double> grid_attitude;
};

/// Summary of the experiment.
struct NeesSummary {
  std::vector<NeesRun> runs;
  double nees_position_mean = 0.0;  ///< mean over runs of the time averages
  double nees_attitude_mean = 0.0;
  double bound_lo = 0.0;  ///< AverageNeesBounds(3, runs, confidence)
  double bound_hi = 0.0;
  /// Per time step: steps valid in every run, fractions inside the bounds
  /// and the mean over those steps of the run-averaged NEES.
  std::size_t grid_steps = 0;
  double grid_position_inside = 0.0;
  double grid_attitude_inside = 0.0;
  double grid_position_mean = 0.0;
  double grid_attitude_mean = 0.0;
  bool position_inside = false;
  bool attitude_inside = false;
  bool Passed() const { return position_inside && attitude_inside; }
};

/// Runs the experiment (progress on `err`). Throws std::invalid_argument for
/// bad options and whatever loading the scenario throws.
NeesSummary RunNeesExperiment(const NeesCommandOptions& options, std::ostream& err);

/// Runs the experiment and prints the setup, the seed derivation, a per-run
/// table (seed, distance, final error, NEES position and attitude, samples,
/// rejections), the summary (Monte Carlo averages against the bounds, the
/// per-time-step figures) and as the last line exactly
///   RESULT runs=N nees_pos_mean=... nees_att_mean=... bound_lo=... bound_hi=...
/// Returns kExitOk if both averages are inside the bounds, kExitCheckFailed if
/// not, kExitBadInput (message on `err`) for bad options or scenarios.
int RunNees(const NeesCommandOptions& options, std::ostream& out, std::ostream& err);

/// Adds `rover-sim nees` to `app` (see subcommand.h).
Subcommand AddNeesCommand(CLI::App& app);

}  // namespace rover::sim::experiments

#endif  // ROVER_HIL_SIM_EXPERIMENTS_NEES_COMMAND_H_
