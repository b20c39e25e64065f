#ifndef ROVER_MAPPING_SLAM_TEAM_GRAPH_H_
#define ROVER_MAPPING_SLAM_TEAM_GRAPH_H_

// The team's pose graph rebuilt from several rovers' mapd logs, for the
// team's map after a mission (rover-log map, rover-team's evaluation). Each
// rover's log holds its own factors and those the team sent it; read
// together, every factor counts once. Each rover anchored its own map with a
// prior on its first origin; the team's map is in the frame of the lowest
// robot id's prior, so the other priors are left out and the other rovers
// hang off it by their inter-robot factors (detections, matches). A rover
// that no such factor links stays unplaced.

#include <map>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include "mapping/slam/graph_log.h"

namespace rover::mapping {

struct TeamGraphSolution {
  int anchor_robot = -1;  ///< whose prior frames the team's map
  /// Every placed origin, T_anchor_origin by (robot, local frame id); the
  /// anchor's prior frame is the identity.
  std::map<std::pair<int, int64_t>, Eigen::Isometry3d> origins;
  std::vector<int> robots;           ///< every robot with factors in the logs
  std::vector<int> unplaced_robots;  ///< of those, with no origin linked to the anchor
  uint64_t factors = 0;
  uint64_t priors_left_out = 0;
  std::vector<std::string> problems;  ///< from reading the logs
};

/// Solves the team's graph from `logs`, read from mapd logs of any rovers
/// (ReadGraphLogs). Throws std::runtime_error if no log holds a prior.
TeamGraphSolution SolveTeamGraph(const GraphLogContents& logs);

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_SLAM_TEAM_GRAPH_H_
