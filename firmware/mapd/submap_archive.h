#ifndef ROVER_FIRMWARE_MAPD_SUBMAP_ARCHIVE_H_
#define ROVER_FIRMWARE_MAPD_SUBMAP_ARCHIVE_H_

// Where mapd's finished submaps go: into mapd's log as standard messages
// (their serialised bytes are what the bandwidth figure counts), and into
// the global map, placed by chaining the switch records that opened them
// (the pose graph's optimised origins replace this chain when it runs in
// mapd). On Close the composed map is exported for octovis (.bt, .ot) and
// point-cloud viewers (.ply).

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>

#include <Eigen/Geometry>

#include "core/log/msgs/geometry_msgs.h"
#include "core/log/msgs/nav_msgs.h"
#include "core/log/msgs/rover_msgs.h"
#include "firmware/mapd/map_log.h"
#include "mapping/compose/map_composer.h"
#include "mapping/submap/submap.h"

namespace rover::mapd {

struct SubmapRecord;
struct MapdStats;

/// What archiving one submap cost.
struct ArchivedBytes {
  uint64_t octree = 0;
  uint64_t cloud = 0;
};

class SubmapArchive {
 public:
  /// Writes `log_stem`.mcap now and the global map to `log_stem`.bt, .ot and
  /// .ply on Close. `log_stem` empty: nothing is written, submaps are only
  /// composed. Throws log::McapError naming the log path if it cannot be
  /// created.
  SubmapArchive(const std::string& log_stem, const std::string& robot_name,
                const mapping::MapComposerOptions& composer);
  ~SubmapArchive();

  /// A new submap record (mapped or not): extends the chain of frames that
  /// places submaps in the map frame (the first record's frame).
  void OpenFrame(const SubmapRecord& record);
  /// Logs `submap` (finished) with its record and adds it to the global map.
  /// Returns the serialised sizes of its octree and cloud messages.
  ArchivedBytes Add(const SubmapRecord& record, const mapping::Submap& submap);
  /// Logs the traversability grid.
  void LogTraversability(const log::nav_msgs::OccupancyGrid& grid);
  /// Logs one pose-graph factor and flushes it to disk (a crash from then on
  /// keeps it).
  void LogFactor(const log::rover_msgs::GraphFactor& factor);
  /// Logs the graph's origins after an update that changed them.
  void LogOrigins(const log::rover_msgs::SubmapOrigins& origins);
  /// Logs the global pose after an update.
  void LogGlobalPose(const log::geometry_msgs::PoseWithCovarianceStamped& pose);
  /// Places the submaps at the pose graph's origins (T_world_frame by local
  /// frame id): archived submaps move in the composed map, later ones are
  /// placed there. The map frame stays the first submap's frame.
  void SetOrigins(const std::map<int64_t, Eigen::Isometry3d>& T_world_frame);
  /// Writes the statistics into the log, closes it and exports the composed
  /// map. Idempotent.
  void Close(const std::map<std::string, std::string>& statistics);

  const std::string& log_path() const { return log_path_; }
  const mapping::MapComposer& composer() const { return composer_; }
  /// Submaps left out of the global map: their origin does not chain to the
  /// first submap's frame.
  uint64_t unplaced() const { return unplaced_; }

 private:
  std::string log_stem_;
  std::string robot_name_;
  std::string log_path_;
  std::unique_ptr<MapLog> log_;
  mapping::MapComposer composer_;
  /// T_map_local per local frame id; the map frame is the first submap's.
  std::map<uint32_t, Eigen::Isometry3d> T_map_frame_;
  std::optional<uint32_t> map_frame_;                     ///< the first submap's frame
  std::map<uint32_t, uint32_t> composed_index_of_frame_;  ///< archived submaps
  uint64_t unplaced_ = 0;
  bool closed_ = false;
};

}  // namespace rover::mapd

#endif  // ROVER_FIRMWARE_MAPD_SUBMAP_ARCHIVE_H_
