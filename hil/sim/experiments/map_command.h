#ifndef ROVER_HIL_SIM_EXPERIMENTS_MAP_COMMAND_H_
#define ROVER_HIL_SIM_EXPERIMENTS_MAP_COMMAND_H_

// `rover-sim map`: the quality of the map of a simulated mission against the
// simulator's ground truth (map_evaluation.h), and the submap bandwidth.
// Reads the mission's flight log (roverd: frame switches, estimates, the
// mission's scenario, rover, seed and start time) and mapd's log(s) (submaps),
// composes the global map in the world frame and scores it.

#include <limits>
#include <ostream>
#include <string>
#include <vector>

#include "core/cli/subcommand.h"
#include "hil/sim/experiments/map_evaluation.h"
#include "hil/sim/experiments/tag_evaluation.h"

namespace rover::sim::experiments {

using cli::kExitBadInput;
using cli::Subcommand;

struct MapCommandOptions {
  std::string mission_log;
  std::vector<std::string> mapd_logs;
  /// Override the scenario, seed and rover recorded in the mission log
  /// (-1: the log's; a log without a rover is rover 0, the scenario's route).
  std::string scenario;
  int64_t seed = -1;
  int64_t rover = -1;
  /// Also write the world-frame map to STEM.bt and STEM.ply.
  std::string export_stem;
  MapQualityOptions quality;
  /// Re-solve the logged graph with this share of its matches false
  /// (mapping::MakeFalseSubmapMatches); 0: not done.
  double false_match_fraction = 0.0;
  uint64_t false_match_seed = 1;
  /// Diagnostic: also re-solve with the frame switches' sigmas scaled.
  double switch_sigma_scale = 1.0;
  /// Diagnostic: compose the submaps at their true origins.
  bool true_origins = false;
  /// Re-run loop closing offline on the logged submaps (loop_replay.h).
  bool rematch = false;
  bool rematch_reapply_switch_noise = false;
  /// With rematch: a YAML file of loop-closing options (LoopCloserOptions
  /// keys: data, pairing, matcher, ...) to replay with instead of mapd's
  /// defaults; empty: the defaults.
  std::string rematch_loop_config;
  /// With rematch: explain every pair of submaps whose obstacle boxes
  /// overlap at the true origins (matched, or why not).
  bool explain_pairs = false;
};

/// What RunMap measured (for rover-launch's RESULT line).
struct MapResult {
  MapQuality quality;
  uint64_t submaps = 0;
  double submap_bytes_per_s = 0.0;
  double raw_stereo_bytes_per_s = 0.0;
  double compose_ms = 0.0;
  uint64_t map_memory_bytes = 0;
  /// The pose graph's last global pose against the truth at its stamp (nan
  /// when mapd logged none), over the true distance driven up to then.
  double slam_final_error_m = std::numeric_limits<double>::quiet_NaN();
  double slam_final_error_pct = std::numeric_limits<double>::quiet_NaN();
  uint64_t loop_closures = 0;  ///< submap matches in the graph (c factors)
  /// Those within 0.2 m and 1 deg of the truth (the origins' true poses: the
  /// true body pose, x y z yaw, at each frame switch), and their share.
  uint64_t loop_closures_valid = 0;
  double loop_closure_precision = std::numeric_limits<double>::quiet_NaN();
  /// From mapd's log statistics (the last log that has them; nan if none).
  double matcher_ms_p50 = std::numeric_limits<double>::quiet_NaN();
  double graph_update_ms_p99 = std::numeric_limits<double>::quiet_NaN();
  /// The frame switches' mean NEES against the truth (x, y, z, yaw: 4 when
  /// their covariances are consistent; nan without switches).
  double frame_switch_nees = std::numeric_limits<double>::quiet_NaN();
  uint64_t graph_origins = 0;  ///< submaps placed at the graph's origins
  /// With false_match_fraction: the logged graph re-solved as it is, and
  /// with the false matches added (final error, % of distance).
  uint64_t false_matches = 0;
  double resolved_error_pct = std::numeric_limits<double>::quiet_NaN();
  double false_match_error_pct = std::numeric_limits<double>::quiet_NaN();
  /// AprilTags: accepted detections logged, o factors in the graph, and the
  /// accepted landmark detections' NEES against the truth (tag_evaluation.h).
  TagScore tags;
  uint64_t tag_factors = 0;
  /// With o factors in the graph: the logged graph re-solved whole, and
  /// without the tag sightings (v and o), final error % of distance: what
  /// the tags did on the same run.
  double slam_resolved_error_pct = std::numeric_limits<double>::quiet_NaN();
  double slam_without_tags_error_pct = std::numeric_limits<double>::quiet_NaN();
  /// In a team: factors in this rover's log that name other rovers, and the
  /// logged graph re-solved whole and with this rover's own factors alone
  /// (final error, % of distance): what the team did for this rover.
  uint64_t team_factors = 0;
  double slam_team_resolved_error_pct = std::numeric_limits<double>::quiet_NaN();
  double slam_alone_error_pct = std::numeric_limits<double>::quiet_NaN();
};

/// One rover of a team mission: its flight log and its mapd logs.
struct TeamMapRover {
  std::string mission_log;
  std::vector<std::string> mapd_logs;
};

/// The team's map: every rover's submaps at the team graph's origins
/// (mapping::SolveTeamGraph over all mapd logs, in the lowest robot's frame),
/// scored against the world like one rover's map.
struct TeamMapResult {
  MapQuality quality;
  uint64_t submaps = 0;
  uint64_t submaps_placed = 0;
  std::vector<int> unplaced_robots;  ///< no factor linked them to the anchor
  double compose_ms = 0.0;
};

/// Throws std::runtime_error naming the file or the problem.
TeamMapResult EvaluateTeamMap(const std::vector<TeamMapRover>& rovers, std::ostream& report,
                              const MapQualityOptions& quality = {});

/// Evaluates; throws std::runtime_error naming the file or the problem.
MapResult EvaluateMission(const MapCommandOptions& options, std::ostream& report);

/// The RESULT fields of `r`: "map_precision=... map_recall=... ...".
std::string MapResultFields(const MapResult& r);

/// Runs the evaluation, prints the report and, as the last line,
///   RESULT map_precision=... map_recall=... obstacle_precision=...
///          obstacle_recall=... submaps=... submap_bytes_per_s=...
///          raw_stereo_bytes_per_s=... loop_closures=...
///          loop_closure_precision=... matcher_ms_p50=... graph_update_ms_p99=...
///          frame_switch_nees=... tag_detections=... tag_factors=...
///          tag_nees_in_bound_pct=... slam_without_tags_err_pct=...
/// Errors go to `err`; returns kExitBadInput for unusable input.
int RunMap(const MapCommandOptions& options, std::ostream& out, std::ostream& err);

/// Adds `rover-sim map` to `app` (see subcommand.h).
Subcommand AddMapCommand(CLI::App& app);

/// Adds --obstacle-radius-m and --obstacle-view-range-m, the obstacle
/// scoring options shared by `rover-sim map` and `rover-sim terrain`.
void AddObstacleScoringOptions(CLI::App* cmd, MapQualityOptions* quality);

}  // namespace rover::sim::experiments

#endif  // ROVER_HIL_SIM_EXPERIMENTS_MAP_COMMAND_H_
