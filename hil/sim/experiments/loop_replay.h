#ifndef ROVER_HIL_SIM_EXPERIMENTS_LOOP_REPLAY_H_
#define ROVER_HIL_SIM_EXPERIMENTS_LOOP_REPLAY_H_

// Loop closing re-run offline on a mission's logged submaps: the pose graph
// from the logged prior and frame switches, and mapd's pairing and matcher
// (mapd's LoopCloser defaults) run in order, as if matching took no time.
// Each submap joins the pairing when its frame switch arrives; every
// candidate pair is matched before the next switch; accepted matches join
// the graph at once. The live mapd matches fewer pairs when the mission
// ends before its matching thread catches up, so this is what the logged
// submaps allow, and it runs in seconds, deterministically: a test bed for
// the pairing, matcher and noise-model options on real mission data.

#include <Eigen/Geometry>
#include <map>
#include <ostream>
#include <vector>

#include "firmware/mapd/loop_closer.h"
#include "mapping/compose/submap_log.h"
#include "mapping/slam/frame_switch_noise.h"
#include "mapping/slam/graph_log.h"

namespace rover::sim::experiments {

struct LoopReplayOptions {
  /// The pairing, matcher and matching-data options (mapd's defaults).
  mapd::LoopCloserOptions loop{};
  /// Put the logged frame switches' covariances through this model again
  /// (for logs written before mapd applied it); off: as logged.
  bool reapply_switch_noise = false;
  mapping::FrameSwitchNoiseOptions switch_noise{};
  /// True origins by frame (simulation): each match's error is reported.
  std::map<int64_t, Eigen::Isometry3d> true_origins;
  /// After the replay, one line per pair of submaps whose obstacle boxes
  /// overlap at the true origins: what the pairing made of it at the end
  /// (matched, or the rule that kept it out), to see which revisits loop
  /// closing missed and why.
  bool explain_pairs = false;
};

/// The definition of a valid loop closure the mission reports use: the
/// match T_a_b within 0.2 m and 1 deg of the true T_a_b.
inline constexpr double kValidLoopClosureTranslationM = 0.2;
inline constexpr double kValidLoopClosureRotationDeg = 1.0;
bool IsValidLoopClosure(const Eigen::Isometry3d& T_a_b, const Eigen::Isometry3d& T_a_b_true);

/// What the replay found, one line per match in `report`.
struct LoopReplayResult {
  /// The logged graph's prior and frame switches, the replay's matches
  /// (c factors), the final origins and the final global pose moved with
  /// its frame's origin.
  mapping::GraphLogContents graph;
  int pairs_matched = 0;
  int matches_accepted = 0;
  int matches_valid = 0;  ///< accepted within 0.2 m and 1 deg of the true origins
  int submaps_suitable = 0;
};

/// Replays loop closing on `logged` (the graph) and `submaps` (the same
/// mapd log's submaps). Throws std::runtime_error if the logged graph has
/// no prior or no final origins.
LoopReplayResult ReplayLoopClosing(const mapping::GraphLogContents& logged,
                                   const mapping::SubmapLog& submaps,
                                   const LoopReplayOptions& options, std::ostream& report);

}  // namespace rover::sim::experiments

#endif  // ROVER_HIL_SIM_EXPERIMENTS_LOOP_REPLAY_H_
