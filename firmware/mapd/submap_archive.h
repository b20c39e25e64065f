#ifndef ROVER_FIRMWARE_MAPD_SUBMAP_ARCHIVE_H_
#define ROVER_FIRMWARE_MAPD_SUBMAP_ARCHIVE_H_

// Where mapd's finished submaps go: into mapd's log as standard messages
// (their serialised bytes are what the bandwidth figure counts). The archive
// keeps where each local frame sits in the map frame (the first submap's),
// by chaining the switch records that opened the frames; the pose graph's
// optimised origins replace this chain when it runs in mapd. On Close the
// global map is composed from the log, each submap at its frame's final
// origin, and exported for octovis (.bt, .ot) and point-cloud viewers
// (.ply).
//
// Submaps are not kept in memory: a long mission makes hundreds, and the
// log already holds them. The export reads them back a few at a time, so
// it needs memory for the map, not for every submap. As the host tools do,
// it composes the logged octrees, whose voxels are occupied or free (the
// radio's binary form), not their log-odds.

#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>

#include <Eigen/Geometry>

#include "core/log/msgs/diagnostic_msgs.h"
#include "core/log/msgs/geometry_msgs.h"
#include "core/log/msgs/nav_msgs.h"
#include "core/log/msgs/rover_msgs.h"
#include "firmware/mapd/map_log.h"
#include "mapping/compose/map_composer.h"
#include "mapping/submap/submap.h"
#include "mapping/team/team_submap.h"

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
  /// .ply on Close. `log_stem` empty: nothing is written or composed. Throws
  /// log::McapError naming the log path if it cannot be created, and
  /// std::invalid_argument for invalid composer options.
  SubmapArchive(const std::string& log_stem, const std::string& robot_name,
                const mapping::MapComposerOptions& composer);
  ~SubmapArchive();

  /// A new submap record (mapped or not): extends the chain of frames that
  /// places submaps in the map frame (the first record's frame).
  void OpenFrame(const SubmapRecord& record);
  /// Logs `submap` (finished) with its record. Returns the serialised sizes
  /// of its octree and cloud messages; `messages` (if given) gets the three
  /// messages as logged (for the team).
  ArchivedBytes Add(const SubmapRecord& record, const mapping::Submap& submap,
                    mapping::TeamSubmap* messages = nullptr);
  /// Logs the traversability grid.
  void LogTraversability(const log::nav_msgs::OccupancyGrid& grid);
  /// Logs one pose-graph factor and flushes it to disk (a crash from then on
  /// keeps it).
  void LogFactor(const log::rover_msgs::GraphFactor& factor);
  /// Logs the graph's origins after an update that changed them.
  void LogOrigins(const log::rover_msgs::SubmapOrigins& origins);
  /// Logs one tag observation (mapping::kTagDetectionTopic).
  void LogTagDetection(const log::rover_msgs::TagDetection& detection);
  /// Logs mapd's own diagnostics (its memory) on /diagnostics.
  void LogDiagnostics(const log::diagnostic_msgs::DiagnosticArray& diagnostics);
  /// Logs one message of the team link on `topic` (mapping::kTeamSentTopic
  /// or kTeamReceivedTopic) and flushes it (a crash keeps it).
  void LogTeamMessage(std::string_view topic, const log::rover_msgs::TeamMessage& message);
  /// Logs the global pose after an update.
  void LogGlobalPose(const log::geometry_msgs::PoseWithCovarianceStamped& pose);
  /// Places the submaps at the pose graph's origins (T_world_frame by local
  /// frame id), for the map composed on Close. The map frame stays the
  /// first submap's frame.
  void SetOrigins(const std::map<int64_t, Eigen::Isometry3d>& T_world_frame);
  /// Writes the statistics into the log, closes it, composes the global map
  /// from it and exports the map. A map that cannot be composed or written
  /// is reported on stderr; the log stays. Idempotent.
  void Close(const std::map<std::string, std::string>& statistics);

  const std::string& log_path() const { return log_path_; }
  /// After Close: submaps composed into the exported map, and those left
  /// out because their frame does not chain to the first submap's.
  std::size_t composed_submaps() const { return composed_submaps_; }
  uint64_t unplaced() const { return unplaced_; }

 private:
  void ExportMap();

  std::string log_stem_;
  std::string robot_name_;
  std::string log_path_;
  std::unique_ptr<MapLog> log_;
  mapping::MapComposerOptions composer_options_;
  /// T_map_local per local frame id; the map frame is the first submap's.
  std::map<uint32_t, Eigen::Isometry3d> T_map_frame_;
  std::optional<uint32_t> map_frame_;  ///< the first submap's frame
  std::size_t composed_submaps_ = 0;
  uint64_t unplaced_ = 0;
  bool closed_ = false;
};

}  // namespace rover::mapd

#endif  // ROVER_FIRMWARE_MAPD_SUBMAP_ARCHIVE_H_
