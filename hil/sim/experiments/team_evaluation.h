#ifndef ROVER_HIL_SIM_EXPERIMENTS_TEAM_EVALUATION_H_
#define ROVER_HIL_SIM_EXPERIMENTS_TEAM_EVALUATION_H_

// The team mission's result (rover-team): each rover's RESULT line (from its
// rover-launch, the map's fields included) extended by its team fields, and
// one line for the team. The team fields come from the rovers' mapd logs:
// the graph factors every rover logged (its own and those it received) and
// mapd's statistics.
//
// Inter-robot closures are the factors that tie one rover's map to
// another's: submap matches between two rovers' submaps (c), robot
// detections (d), and sightings (o) of a landmark another rover has also
// seen.

#include <cstdint>
#include <limits>
#include <ostream>
#include <string>
#include <vector>

namespace rover::sim::experiments {

/// One rover of a finished team mission.
struct TeamRoverRun {
  std::string name;         ///< "rover_a", ...
  int robot = 0;            ///< its graph robot id
  std::string folder;       ///< its logs (mission-*.mcap, mapd-*.mcap)
  std::string result_line;  ///< its rover-launch RESULT line ("" if none)
};

struct TeamResult {
  std::vector<std::string> rover_lines;  ///< "RESULT ... robot=0 link_bytes_per_s=..."
  std::string team_line;                 ///< "RESULT team ..."
  uint64_t inter_robot_matches = 0;
  uint64_t robot_detections = 0;
  uint64_t shared_landmark_sightings = 0;
  uint64_t inter_robot_closures = 0;  ///< the three above
  /// Over the rovers: the worst final SLAM error and link rate.
  double slam_final_err_pct_max = std::numeric_limits<double>::quiet_NaN();
  double link_bytes_per_s_max = std::numeric_limits<double>::quiet_NaN();
  /// The team's map (every rover's submaps at the team graph's origins)
  /// against the world.
  double team_map_precision = std::numeric_limits<double>::quiet_NaN();
  double team_map_recall = std::numeric_limits<double>::quiet_NaN();
  uint64_t team_submaps_placed = 0;
  uint64_t team_submaps = 0;
};

/// The value of `key=` in a RESULT line ("" if absent).
std::string ResultLineField(const std::string& line, const std::string& key);

/// Reads the rovers' mapd logs and writes what it found to `report`. A rover
/// without a RESULT line or logs is reported and scored as nan.
TeamResult EvaluateTeam(const std::string& scenario, const std::vector<TeamRoverRun>& runs,
                        std::ostream& report);

}  // namespace rover::sim::experiments

#endif  // ROVER_HIL_SIM_EXPERIMENTS_TEAM_EVALUATION_H_
