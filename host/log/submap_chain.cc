#include "host/log/submap_chain.h"

#include "core/geometry/yaw.h"

namespace rover::host {

Eigen::Isometry3d SubmapOriginTransform(const log::rover_msgs::SubmapInfo& info) {
  return GravityAlignedTransform(
      Eigen::Vector3d(info.p_previous_origin_m[0], info.p_previous_origin_m[1],
                      info.p_previous_origin_m[2]),
      info.yaw_previous_origin_rad);
}

std::map<uint32_t, Eigen::Isometry3d> ChainSubmapOrigins(
    const std::vector<mapping::LoggedSubmap>& submaps) {
  std::map<uint32_t, Eigen::Isometry3d> origins;
  if (submaps.empty()) return origins;
  origins.emplace(submaps.front().info.frame_id, Eigen::Isometry3d::Identity());
  // Until nothing changes, so that a switch logged before the one it builds
  // on still chains. At most one pass per frame.
  for (bool grew = true; grew;) {
    grew = false;
    for (const mapping::LoggedSubmap& s : submaps) {
      const log::rover_msgs::SubmapInfo& info = s.info;
      if (!info.has_origin || origins.count(info.frame_id) > 0) continue;
      const auto previous = origins.find(info.previous_frame_id);
      if (previous == origins.end()) continue;
      origins.emplace(info.frame_id, previous->second * SubmapOriginTransform(info));
      grew = true;
    }
  }
  return origins;
}

std::string WhyUnplaced(const log::rover_msgs::SubmapInfo& info,
                        const std::map<uint32_t, Eigen::Isometry3d>& origins) {
  if (origins.count(info.frame_id) > 0) return "placed";
  if (!info.has_origin) {
    return "no origin recorded (mapd joined frame " + std::to_string(info.frame_id) + " half-way)";
  }
  return "its origin starts in frame " + std::to_string(info.previous_frame_id) +
         ", which no placed submap reaches";
}

}  // namespace rover::host
