#ifndef ROVER_HIL_SIM_EXPERIMENTS_FILTER_COMMAND_H_
#define ROVER_HIL_SIM_EXPERIMENTS_FILTER_COMMAND_H_

// `rover-sim filter`: the local reference filter alone on a simulated scenario
// (hil/sim/estimator_feed: FilterFeed + RunFilter), scored against the
// simulator's ground truth: ATE, RPE, drift as % of distance, attitude error,
// NEES, rejections. Also the pieces `rover-sim nees` shares with it: the
// simulation setup, the seed derivation and the parallel run loop.
//
// Seeds. Run i (0-based) of a command with --seed S uses the run seed S + i,
// passed to FilterFeed, which derives from it: the world (terrain, rocks,
// posts), every IMU stream (white noise, bias random walks, turn-on biases,
// sample-time jitter: IMU seed = scenario IMU seed ^ run seed * golden ratio),
// and the synthetic VO's noise, frame drops and latency (StreamSeed(run seed,
// stream)). The wheel model's streams (slip, velocity noise, CAN timing) are
// seeded by the `seed` key of the scenario's wheels file (hil/config/
// wheels.yaml) and do NOT change with the run seed; only the terrain under the
// wheels does. The reports say so when wheel speeds are used.

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <ostream>
#include <string>
#include <vector>

#include "core/cli/subcommand.h"
#include "estimator/eskf/eskf_options.h"
#include "estimator/eval/trajectory.h"
#include "hil/sim/estimator_feed/filter_feed.h"
#include "hil/sim/estimator_feed/filter_run.h"
#include "hil/sim/scenario/scenario.h"

namespace rover::sim::experiments {

using cli::kExitBadInput;
using cli::kExitCheckFailed;
using cli::kExitOk;
using cli::Subcommand;

/// What to simulate and how to configure the filter (shared by sim and nees).
struct SimSetup {
  std::string scenario = "short";
  /// Synthetic VO noise preset: "ideal-consistent" or "realistic".
  std::string preset = "realistic";
  /// Wheel speeds from the CAN bus into the filter (and the filter's wheel
  /// and zero-velocity updates, which need them).
  bool wheels = true;
  /// Simulate the IMU with white noise, bias walks and turn-on biases only
  /// (no scale-factor and misalignment errors, which the filter does not model).
  bool imu_white_only = false;
  double switch_distance_m = 0.0;  ///< frame switch every D metres (0: none)
  double max_duration_s = 0.0;     ///< simulated seconds (0: the whole route)
  double drop_probability = 0.0;   ///< VO frame drops
  /// Scales the VO covariance the filter assumes (EskfOptions
  /// relative_pose.covariance_inflation); 1: the stated covariance, which is
  /// the one the simulator draws from.
  double vo_covariance_inflation = 1.0;
  /// Where scenarios and sensor configs live (empty: DefaultScenarioDir(),
  /// DefaultSimConfigDir()).
  std::string scenario_dir;
  std::string config_dir;

  /// Throws std::invalid_argument naming the first bad value.
  void Validate() const;
  /// "VO preset realistic, wheels on, IMU full error model, ..." (one line, no newline).
  std::string Describe() const;
};

/// The scenario of `setup`, with the IMU reduced to white noise and biases
/// if setup.imu_white_only. Throws for unknown names or bad files.
sim::Scenario LoadSimScenario(const SimSetup& setup);
/// The feed options of `setup`.
sim::FilterFeedOptions SimFeedOptions(const SimSetup& setup);
/// EskfOptionsForFeed(feed) with setup's VO covariance inflation.
estimator::EskfOptions SimFilterOptions(const sim::FilterFeed& feed, const SimSetup& setup);
/// Registers the options both simulator commands share on `cmd`: --preset,
/// --wheels (into `*wheels`, "on"/"off"), --jobs (into `*jobs`),
/// --switch-distance-m, --duration-s, --imu-white-only, --vo-cov-inflation.
void AddSimSetupOptions(CLI::App* cmd, SimSetup* setup, std::string* wheels, int* jobs);
/// The seed of run `run` (0-based) under the command's base seed: base + run.
uint64_t RunSeed(uint64_t base_seed, int run);
/// The note about the wheel model's fixed seed (empty when wheels are off).
std::string WheelSeedNote(const SimSetup& setup, const sim::Scenario& scenario);

/// Calls run(i) for i in [0, runs) on min(jobs, runs) threads (jobs >= 1),
/// printing "`label`: run k/N done (...), ETA ..." to `err` as runs finish.
/// run(i) must only touch state of run i. Rethrows the first exception of
/// the lowest-numbered failing run after all threads have finished.
void RunInParallel(int runs, int jobs, const std::string& label,
                   const std::function<std::string(int)>& run, std::ostream& err);

/// Sum over input kinds of the rejections after initialisation.
uint64_t RejectionsAfterInit(const sim::FilterRunResult& result);
/// Gated rejections (after initialisation, every kind).
uint64_t GatedRejections(const sim::FilterRunResult& result);

/// The filter's estimate and the ground truth as trajectories in the true
/// frame 0 (the true body position and yaw at initialisation, which is where
/// the filter's frame 0 is by construction), the estimate chained through the
/// filter's own frame-switch records. One pose per `step_s` of filter time
/// (the first output at or after each multiple of step_s after the
/// feed start); needs result.samples (FilterRunOptions::keep_samples).
struct SimTrajectories {
  rover::eval::Trajectory estimate;
  rover::eval::Trajectory truth;
};
SimTrajectories BuildSimTrajectories(const sim::FilterFeed& feed,
                                     const sim::FilterRunResult& result, double step_s = 0.1);

struct FilterCommandOptions {
  SimSetup setup;
  uint64_t seed = 1;
  int runs = 1;
  int jobs = 1;
  /// RPE segment lengths [m]; the 10 m segment (or the nearest shorter one
  /// with results) is quoted in RESULT.
  std::vector<double> segments_m = {1, 5, 10, 20, 50};
  /// If not empty: every output's errors and sigmas of the first run (CSV).
  std::string csv_path;
};

/// Runs the filter on `options.runs` simulations of the scenario (run seeds
/// seed, seed + 1, ...) and prints, for one run: the feed and filter
/// summary, distance, position error per frame and global (frame-0 chain;
/// final, mean, max, in m and % of distance), attitude error, NEES, clone
/// counters, rejections, the ATE table (no alignment: frame 0 is the true
/// frame) and the RPE table per segment length; for several runs: one table
/// row per run with those figures and their means; and as the last line
///   RESULT scenario=NAME runs=N distance_m=... final_err_m=... final_err_pct=...
///          mean_err_pct=... ate_rmse_m=... rpe_trans_pct=... rpe_rot_deg_per_m=...
///          nees_pos_mean=... nees_att_mean=...
/// (means over runs; distance is the horizontal distance driven from
/// initialisation, errors are the global position errors; "nan" for anything
/// that cannot be computed). Progress goes to `err`. Returns kExitOk;
/// kExitCheckFailed (after the report) if the filter never initialised in
/// some run; kExitBadInput (message on `err`) for bad options or scenarios.
int RunFilterCommand(const FilterCommandOptions& options, std::ostream& out, std::ostream& err);

/// Adds `rover-sim filter` to `app` (see subcommand.h).
Subcommand AddFilterCommand(CLI::App& app);

}  // namespace rover::sim::experiments

#endif  // ROVER_HIL_SIM_EXPERIMENTS_FILTER_COMMAND_H_
