#ifndef ROVER_MAPPING_COMPOSE_SUBMAP_LOG_H_
#define ROVER_MAPPING_COMPOSE_SUBMAP_LOG_H_

// Reading maps back out of flight logs, for the host tools (rover-log map,
// rover-sim map): the submaps mapd logged (rover_msgs/SubmapInfo with its
// octomap_msgs/Octomap and sensor_msgs/PointCloud2, matched by header), and
// the filter's frame switches from roverd's log, chained into each local
// frame's origin in frame 0. roverd's log has every switch even when mapd
// restarted, so submaps of several mapd logs land in one frame.

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <octomap/OcTree.h>
#include <Eigen/Geometry>

#include "core/log/msgs/rover_msgs.h"
#include "mapping/compose/map_composer.h"
#include "mapping/submap/cloud_point.h"

namespace rover::mapping {

/// The topics mapd logs on.
inline constexpr const char* kSubmapInfoTopic = "/mapd/submap/info";
inline constexpr const char* kSubmapOctomapTopic = "/mapd/submap/octomap";
inline constexpr const char* kSubmapCloudTopic = "/mapd/submap/cloud";
inline constexpr const char* kTraversabilityTopic = "/mapd/traversability";

/// One logged submap.
struct LoggedSubmap {
  log::rover_msgs::SubmapInfo info;
  std::shared_ptr<const octomap::OcTree> octree;
  std::shared_ptr<const PointCloud> cloud;
};

/// What a mapd log holds.
struct SubmapLog {
  std::vector<LoggedSubmap> submaps;
  /// The "mapd_statistics" metadata record (absent if mapd did not stop
  /// cleanly).
  std::map<std::string, std::string> statistics;
  uint64_t traversability_grids = 0;
  /// Messages that could not be used, each naming the topic, the log time
  /// and why (an undecodable message, a submap missing its octree or
  /// cloud). Reading goes on past them.
  std::vector<std::string> problems;
};

/// Reads a mapd log. Throws std::runtime_error naming the path if it is not
/// a readable MCAP file; damage inside it (a truncated tail, a bad chunk)
/// ends up in `problems`, with every intact submap still read.
SubmapLog ReadSubmapLog(const std::string& path);

/// T_frame0_frame for every local frame of roverd's log, chained from its
/// rover_msgs/EstimatorFrameSwitch records (frame 0 maps to identity).
/// Throws std::runtime_error naming the path if it is unreadable, or a
/// switch that does not chain (its old frame was never reached).
std::map<uint32_t, Eigen::Isometry3d> ReadFrameOrigins(const std::string& roverd_log_path);

/// Places the submaps of `logs` at `origins` (by SubmapInfo::frame_id) into
/// `composer`, keyed by (log number, submap index) so that submaps of a
/// restarted mapd do not collide. Returns how many had no origin.
std::size_t AddLoggedSubmaps(const std::vector<SubmapLog>& logs,
                             const std::map<uint32_t, Eigen::Isometry3d>& origins,
                             MapComposer* composer);

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_COMPOSE_SUBMAP_LOG_H_
