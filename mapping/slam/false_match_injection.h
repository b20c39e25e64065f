#ifndef ROVER_MAPPING_SLAM_FALSE_MATCH_INJECTION_H_
#define ROVER_MAPPING_SLAM_FALSE_MATCH_INJECTION_H_

// Seeded false submap matches for the rover graph, to measure how the
// graph's robust loss copes with a matcher that is wrong some of the time.
// A false match is made to be tempting, as a real matcher's mistakes are: it
// pairs two origins of one robot that are near each other by the given
// estimates (within near_m, never successive frames), and claims a 4-DoF
// transform (x, y, z, yaw) off their estimated relative pose by 1 to
// max_offset_m and up to max_yaw_offset_rad, with the covariance of a real
// match of the graph (or a 5 cm / 0.5 deg one if there is none): as
// confident as a true one.

#include <cstdint>
#include <map>
#include <vector>

#include <Eigen/Geometry>

#include "mapping/slam/graph_factor_record.h"

namespace rover::mapping {

struct FalseMatchOptions {
  /// Share of all matches (true and false) that are false, in [0, 1).
  double fraction = 0.3;
  double near_m = 15.0;
  double max_offset_m = 4.0;
  double max_yaw_offset_rad = 0.5;
  uint64_t seed = 1;

  /// Throws std::invalid_argument "FalseMatchOptions.<key>: ...".
  void Validate() const;
};

/// False c factors for `factors` (a rover graph as logged) of robot
/// `robot`: n such that n / (n + true matches) is about options.fraction,
/// where the true-match count is at least a fifth of the origins (so a graph
/// without matches still gets some). `T_world_origin` are the origin
/// estimates by local frame id. Ids continue after the largest id in
/// `factors`. Deterministic in options.seed. Returns fewer if there are not
/// enough near pairs; throws std::invalid_argument for invalid options.
std::vector<GraphFactorRecord> MakeFalseSubmapMatches(
    const std::vector<GraphFactorRecord>& factors, int robot,
    const std::map<int64_t, Eigen::Isometry3d>& T_world_origin, const FalseMatchOptions& options);

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_SLAM_FALSE_MATCH_INJECTION_H_
