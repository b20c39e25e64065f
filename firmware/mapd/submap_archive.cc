#include "firmware/mapd/submap_archive.h"

#include <cmath>
#include <cstdio>
#include <filesystem>

#include "core/geometry/yaw.h"
#include "core/log/msgs/rover_msgs.h"
#include "firmware/mapd/mapd.h"
#include "mapping/compose/map_export.h"
#include "mapping/compose/submap_log.h"
#include "mapping/slam/graph_log.h"
#include "mapping/submap/submap_messages.h"
#include "mapping/tags/tag_log.h"

namespace rover::mapd {
namespace {

// The switch record as a transform: the new frame seen from the old one.
Eigen::Isometry3d TransformOf(const runtime::topics::FrameSwitchMsg& r) {
  return GravityAlignedTransform(
      Eigen::Vector3d(r.p_old_new_m[0], r.p_old_new_m[1], r.p_old_new_m[2]), r.yaw_old_new_rad);
}

}  // namespace

SubmapArchive::SubmapArchive(const std::string& log_stem, const std::string& robot_name,
                             const mapping::MapComposerOptions& composer)
    : log_stem_(log_stem), robot_name_(robot_name), composer_options_(composer) {
  composer_options_.Validate();
  if (!log_stem_.empty()) {
    log_path_ = log_stem_ + ".mcap";
    log_ = std::make_unique<MapLog>(log_path_);
  }
}

SubmapArchive::~SubmapArchive() = default;

void SubmapArchive::OpenFrame(const SubmapRecord& record) {
  if (T_map_frame_.empty()) {
    T_map_frame_[record.frame_id] = Eigen::Isometry3d::Identity();
    map_frame_ = record.frame_id;
    return;
  }
  if (T_map_frame_.count(record.frame_id) != 0) return;  // placed by the graph already
  if (!record.origin) return;                            // joined half-way: cannot be placed
  const auto previous = T_map_frame_.find(record.origin->old_frame_id);
  if (previous == T_map_frame_.end()) return;
  T_map_frame_[record.frame_id] = previous->second * TransformOf(*record.origin);
}

ArchivedBytes SubmapArchive::Add(const SubmapRecord& record, const mapping::Submap& submap,
                                 mapping::TeamSubmap* messages) {
  ArchivedBytes bytes;
  log::std_msgs::Header header;
  header.stamp = log::ToRosTime(record.last_stamp);
  header.frame_id =
      log::FrameId::Truncated("local/" + robot_name_ + "/" + std::to_string(submap.frame_id()));
  mapping::TeamSubmap m;
  m.octomap = mapping::ToOctomapMsg(submap.octree(), header);
  m.cloud = mapping::ToPointCloud2(submap.cloud(), header);
  bytes.octree = log::SerializedSize(m.octomap);
  bytes.cloud = log::SerializedSize(m.cloud);
  log::rover_msgs::SubmapInfo& info = m.info;
  info.header = header;
  info.index = record.index;
  info.frame_id = record.frame_id;
  if (record.origin) {
    info.has_origin = true;
    info.previous_frame_id = record.origin->old_frame_id;
    info.origin_stamp_ns = record.origin->stamp_ns;
    info.p_previous_origin_m = record.origin->p_old_new_m;
    info.yaw_previous_origin_rad = record.origin->yaw_old_new_rad;
    info.origin_covariance = record.origin->covariance;
  }
  info.first_stamp_ns = record.first_stamp.nanoseconds();
  info.last_stamp_ns = record.last_stamp.nanoseconds();
  info.images = static_cast<uint32_t>(submap.images());
  info.distance_m = record.distance_m;
  info.octree_bytes = bytes.octree;
  info.cloud_bytes = bytes.cloud;
  if (log_) {
    const int64_t t = record.last_stamp.nanoseconds();
    log_->Write("/mapd/submap/info", t, info);
    log_->Write("/mapd/submap/octomap", t, m.octomap);
    log_->Write("/mapd/submap/cloud", t, m.cloud);
    log_->Flush();  // a crash from here on keeps this submap
  }
  if (messages != nullptr) *messages = std::move(m);

  // The origin may have arrived after the record was opened (topics are not
  // ordered): chain it now.
  if (T_map_frame_.count(record.frame_id) == 0) OpenFrame(record);
  return bytes;
}

void SubmapArchive::LogFactor(const log::rover_msgs::GraphFactor& factor) {
  if (!log_) return;
  log_->Write(mapping::kGraphFactorTopic, log::FromRosTime(factor.header.stamp).nanoseconds(),
              factor);
  log_->Flush();
}

void SubmapArchive::LogOrigins(const log::rover_msgs::SubmapOrigins& origins) {
  if (!log_) return;
  log_->Write(mapping::kSubmapOriginsTopic, log::FromRosTime(origins.header.stamp).nanoseconds(),
              origins);
}

void SubmapArchive::LogTagDetection(const log::rover_msgs::TagDetection& detection) {
  if (!log_) return;
  log_->Write(mapping::kTagDetectionTopic, log::FromRosTime(detection.header.stamp).nanoseconds(),
              detection);
}

void SubmapArchive::LogDiagnostics(const log::diagnostic_msgs::DiagnosticArray& diagnostics) {
  if (!log_) return;
  log_->Write("/diagnostics", log::FromRosTime(diagnostics.header.stamp).nanoseconds(),
              diagnostics);
}

void SubmapArchive::LogTeamMessage(std::string_view topic,
                                   const log::rover_msgs::TeamMessage& message) {
  if (!log_) return;
  log_->Write(topic, log::FromRosTime(message.header.stamp).nanoseconds(), message);
  log_->Flush();
}

void SubmapArchive::LogGlobalPose(const log::geometry_msgs::PoseWithCovarianceStamped& pose) {
  if (!log_) return;
  log_->Write(mapping::kGlobalPoseTopic, log::FromRosTime(pose.header.stamp).nanoseconds(), pose);
}

void SubmapArchive::SetOrigins(const std::map<int64_t, Eigen::Isometry3d>& T_world_frame) {
  if (!map_frame_) return;
  const auto map_origin = T_world_frame.find(*map_frame_);
  if (map_origin == T_world_frame.end()) return;  // the graph does not reach the map frame
  const Eigen::Isometry3d T_map_world = map_origin->second.inverse();
  for (const auto& [frame, T] : T_world_frame) {
    if (frame < 0 || frame > UINT32_MAX) continue;
    const auto id = static_cast<uint32_t>(frame);
    T_map_frame_[id] = T_map_world * T;
  }
}

void SubmapArchive::LogTraversability(const log::nav_msgs::OccupancyGrid& grid) {
  if (!log_) return;
  log_->Write("/mapd/traversability", log::FromRosTime(grid.header.stamp).nanoseconds(), grid);
}

void SubmapArchive::Close(const std::map<std::string, std::string>& statistics) {
  if (closed_) return;
  closed_ = true;
  if (!log_) return;
  log_->WriteMetadata("mapd_statistics", statistics);
  log_->Close();
  if (T_map_frame_.empty()) return;
  try {
    ExportMap();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "mapd: the global map was not exported: %s\n", e.what());
  }
}

void SubmapArchive::ExportMap() {
  // Submaps are merged a few at a time and released: the export holds the
  // map and those few, not every submap of the mission.
  constexpr int kSubmapsPerMerge = 8;
  mapping::MapComposer composer(composer_options_);
  int unmerged = 0;
  const mapping::SubmapLog read =
      mapping::ForEachLoggedSubmap(log_path_, [&](mapping::LoggedSubmap&& submap) {
        const auto placed = T_map_frame_.find(submap.info.frame_id);
        if (placed == T_map_frame_.end()) {
          ++unplaced_;
          return;
        }
        composer.SetSubmap(submap.info.index, std::move(submap.octree), std::move(submap.cloud),
                           placed->second);
        if (++unmerged == kSubmapsPerMerge) {
          composer.MergeAndRelease();
          unmerged = 0;
        }
      });
  for (const std::string& problem : read.problems) {
    std::fprintf(stderr, "mapd: composing the global map from %s: %s\n", log_path_.c_str(),
                 problem.c_str());
  }
  // The global map in the first submap's frame.
  const octomap::OcTree& map = composer.Compose();
  mapping::WriteOctreeBt(map, log_stem_ + ".bt");
  mapping::WriteOctreeOt(map, log_stem_ + ".ot");
  mapping::WritePly(composer.ComposedCloud(), log_stem_ + ".ply");
  composed_submaps_ = composer.Stats().submaps;
}

}  // namespace rover::mapd
