#ifndef ROVER_MAPPING_COMPOSE_SUBMAP_LOG_H_
#define ROVER_MAPPING_COMPOSE_SUBMAP_LOG_H_

// Reading maps back out of flight logs, for the host tools (rover-log map,
// rover-sim map): the submaps mapd logged (rover_msgs/SubmapInfo with its
// octomap_msgs/Octomap and sensor_msgs/PointCloud2, matched by header), and
// the filter's frame switches from roverd's log, chained into each local
// frame's origin in frame 0. roverd's log has every switch even when mapd
// restarted, so submaps of several mapd logs land in one frame.

#include <cstdint>
#include <functional>
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

/// Reads a mapd log one submap at a time: `on_submap` gets each submap as
/// soon as its info, octree and cloud have been read, in that order of
/// completion (mapd writes the three together, so this is the order it
/// built them). Memory holds the submaps whose messages are still
/// incomplete, not the log. Returns the rest of what the log holds
/// (`submaps` left empty); errors as ReadSubmapLog, and an exception thrown
/// by `on_submap` ends the reading and propagates.
SubmapLog ForEachLoggedSubmap(const std::string& path,
                              const std::function<void(LoggedSubmap&&)>& on_submap);

/// T_frame0_frame for every local frame of roverd's log, chained from its
/// rover_msgs/EstimatorFrameSwitch records (frame 0 maps to identity).
/// Throws std::runtime_error naming the path if it is unreadable, or a
/// switch that does not chain (its old frame was never reached).
std::map<uint32_t, Eigen::Isometry3d> ReadFrameOrigins(const std::string& roverd_log_path);

/// Where one logged submap goes: logs[log].submaps[submap] at T_map_submap.
struct SubmapPlacement {
  std::size_t log = 0;
  std::size_t submap = 0;
  Eigen::Isometry3d T_map_submap = Eigen::Isometry3d::Identity();
};

/// A logged submap that cannot go into the map, and why.
struct UnplacedSubmap {
  enum class Reason {
    kNoOrigin,    ///< no origin for its SubmapInfo::frame_id
    kResolution,  ///< its octree resolution differs from the map's
  };
  std::size_t log = 0;
  std::size_t submap = 0;
  Reason reason = Reason::kNoOrigin;
  double resolution_m = 0.0;  ///< the submap's octree resolution
};

/// The placement of every submap of a set of mapd logs.
struct SubmapPlacements {
  double resolution_m = 0.0;            ///< the map's: the first submap's (mapd uses one for all)
  std::vector<SubmapPlacement> placed;  ///< in log, then submap order (the order mapd built them)
  std::vector<UnplacedSubmap> unplaced;
};

/// The one placement rule of logged submaps: a submap goes at the origin of
/// its frame (`origins` by SubmapInfo::frame_id) if it has one and its octree
/// has the map's resolution (voxels of another size cannot be merged).
SubmapPlacements PlaceLoggedSubmaps(const std::vector<SubmapLog>& logs,
                                    const std::map<uint32_t, Eigen::Isometry3d>& origins);

/// Places the submaps of `logs` by PlaceLoggedSubmaps() into `composer`,
/// keyed by placement order so that submaps of a restarted mapd do not
/// collide. Returns how many could not be placed.
std::size_t AddLoggedSubmaps(const std::vector<SubmapLog>& logs,
                             const std::map<uint32_t, Eigen::Isometry3d>& origins,
                             MapComposer* composer);

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_COMPOSE_SUBMAP_LOG_H_
