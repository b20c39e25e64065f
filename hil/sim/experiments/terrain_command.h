#ifndef ROVER_HIL_SIM_EXPERIMENTS_TERRAIN_COMMAND_H_
#define ROVER_HIL_SIM_EXPERIMENTS_TERRAIN_COMMAND_H_

// `rover-sim terrain`: mapd's per-image pipeline (firmware/mapd LocalMapper:
// SGBM depth, negative edges, error-adaptive steps, obstacle flags into the
// submap cloud) on the scenario's rendered pairs at the true poses, scored
// like `rover-sim map` scores a mission's map (map_evaluation.h). Without
// the estimator, mapd's scheduling or iceoryx in the loop it isolates the
// obstacle classification, is deterministic in (scenario, seed), and runs
// in seconds per seed, so that it can sweep many worlds.

#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

#include "core/cli/subcommand.h"
#include "hil/sim/experiments/map_evaluation.h"

namespace rover::sim::experiments {

struct TerrainCommandOptions {
  std::string scenario = "short";
  std::vector<uint64_t> seeds = {1};
  /// Pairs mapped per second of the route (mapd maps 2 per second on the
  /// simulator board profile).
  double rate_hz = 2.0;
  /// Map only the first this many seconds of the route (0: all of it).
  double max_duration_s = 0.0;
  /// SGBM's path mode (mapping::DisparityOptions::mode); empty: mapd's.
  std::string disparity_mode;
  MapQualityOptions quality;

  /// Throws std::invalid_argument "TerrainCommandOptions.<key>: ...".
  void Validate() const;
};

/// SGBM's depth against the rendered depth along the same rays (kValid
/// pixels, every fourth row and column). A bias here shifts every submap's
/// content along its view, which no pose estimate can absorb.
struct DepthBias {
  /// Median signed disparity error (measured - true) [px].
  double disparity_error_px_p50 = 0.0;
  /// Median relative depth error (measured / true - 1) at true depths of
  /// 1-3 and 3-5 m; NaN where no sample fell. (Further out few pixels stay
  /// kValid, and the median on mixed-300m was -43 %: occlusion edges, where
  /// the rendered depth at the projected pixel is the surface behind.)
  double depth_error_1_3_m = 0.0;
  double depth_error_3_5_m = 0.0;
};

/// One world's figures.
struct TerrainResult {
  uint64_t seed = 0;
  int pairs = 0;
  MapQuality quality;
  DepthBias depth;
  double wall_s = 0.0;
};

/// Maps and scores one world of `options.scenario`. Throws
/// std::invalid_argument for bad options or an unknown scenario.
TerrainResult EvaluateTerrain(const TerrainCommandOptions& options, uint64_t seed);

/// The RESULT fields of `r`: "seed=... obstacle_precision=... ...".
std::string TerrainResultFields(const TerrainResult& r);

/// Runs every seed, prints one line per seed ("RESULT seed=... ...") and a
/// summary with the spread. Errors go to `err`; returns kExitBadInput for
/// unusable input.
int RunTerrain(const TerrainCommandOptions& options, std::ostream& out, std::ostream& err);

/// Adds `rover-sim terrain` to `app` (see subcommand.h).
cli::Subcommand AddTerrainCommand(CLI::App& app);

}  // namespace rover::sim::experiments

#endif  // ROVER_HIL_SIM_EXPERIMENTS_TERRAIN_COMMAND_H_
