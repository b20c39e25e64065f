#ifndef ROVER_MAPPING_SLAM_GRAPH_LOG_H_
#define ROVER_MAPPING_SLAM_GRAPH_LOG_H_

// The pose graph in mapd's MCAP log: every factor as it was added
// (rover_msgs/GraphFactor), the optimised origins after each update
// (rover_msgs/SubmapOrigins) and the global pose s_j (+) v_t
// (geometry_msgs/PoseWithCovarianceStamped). Reading it back rebuilds the
// graph: a restarted mapd carries on from it, `rover-graph` re-optimises it.

#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/log/msgs/geometry_msgs.h"
#include "core/log/msgs/rover_msgs.h"
#include "mapping/slam/graph_factor_record.h"

namespace rover::mapping {

inline constexpr std::string_view kGraphFactorTopic = "/mapd/graph/factors";
inline constexpr std::string_view kSubmapOriginsTopic = "/mapd/graph/origins";
inline constexpr std::string_view kGlobalPoseTopic = "/mapd/global_pose";
/// The team link's messages (rover_msgs/TeamMessage): this rover's, in the
/// order it first published them, and the other rovers' as received.
inline constexpr std::string_view kTeamSentTopic = "/mapd/team/sent";
inline constexpr std::string_view kTeamReceivedTopic = "/mapd/team/received";

/// What one or more mapd logs hold of the graph.
struct GraphLogContents {
  /// Every readable factor once (by robot and id), in log order.
  std::vector<GraphFactorRecord> factors;
  /// The logged message of each factor (same order): re-logging these, not a
  /// re-encoding, keeps every number bit for bit.
  std::vector<log::rover_msgs::GraphFactor> messages;
  /// The last origins and global pose logged (the run's final estimate).
  std::optional<log::rover_msgs::SubmapOrigins> last_origins;
  std::optional<log::geometry_msgs::PoseWithCovarianceStamped> last_global_pose;
  /// Factors left out and damage, each naming the file and the factor.
  std::vector<std::string> problems;
  /// The team messages logged (kTeamSentTopic, kTeamReceivedTopic), each
  /// once by origin, stream and number, in log order.
  std::vector<log::rover_msgs::TeamMessage> team_sent;
  std::vector<log::rover_msgs::TeamMessage> team_received;
  /// The robot of each log's last origins (a mapd logs only its own), by
  /// path; a log without origins is absent.
  std::map<std::string, int> robot_of_log;
  uint64_t duplicates = 0;  ///< Factors read again (a later log repeats an earlier one's).
  bool truncated = false;   ///< Some file ends early (e.g. mapd was killed).
};

/// geometry_msgs/Pose of T, and back.
log::geometry_msgs::Pose ToPoseMsg(const Eigen::Isometry3d& T);
Eigen::Isometry3d FromPoseMsg(const log::geometry_msgs::Pose& pose);

/// A ROS PoseWithCovariance's covariance (rotation about the fixed X, Y, Z
/// axes) from one over [dt (world); dphi (right, body axes)] at rotation R.
Matrix6d RosPoseCovariance(const Eigen::Matrix3d& R_world_body, const Matrix6d& covariance);

/// Moves the frames of `origins` (T_map_frame by local frame id, e.g. chained
/// from the switch records) to the pose graph's optimised origins. The graph
/// is anchored at its lowest frame f0, which must be in `origins`:
/// T_map_f = T_map_f0 * T_graph_f0^-1 * T_graph_f. Returns the number of
/// frames placed by the graph (0 if f0 is not in `origins`).
std::size_t PlaceAtGraphOrigins(const log::rover_msgs::SubmapOrigins& graph,
                                std::map<uint32_t, Eigen::Isometry3d>* origins);

/// The logged final global pose of `logged` moved with its frame's origin as
/// `graph` (the logged graph re-solved, possibly with other factors) places
/// it: its frame is the newest logged origin. Requires last_origins (not
/// empty) and last_global_pose.
Eigen::Isometry3d MovedFinalGlobalPose(const GraphLogContents& logged, const RoverGraph& graph);

/// T_map_graph: the graph's world frame in the map frame of `origins`, by
/// the anchor frame f0 as above; nullopt if f0 is not in `origins`.
std::optional<Eigen::Isometry3d> GraphInMap(const log::rover_msgs::SubmapOrigins& graph,
                                            const std::map<uint32_t, Eigen::Isometry3d>& origins);

/// Reads the graph from `paths` in order (a mission's mapd logs, oldest
/// first). A malformed factor or a damaged chunk is reported in `problems`
/// and left out; the rest is kept. Throws log::McapError if a file cannot be
/// opened at all.
GraphLogContents ReadGraphLogs(const std::vector<std::string>& paths);

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_SLAM_GRAPH_LOG_H_
