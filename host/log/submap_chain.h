#ifndef ROVER_HOST_LOG_SUBMAP_CHAIN_H_
#define ROVER_HOST_LOG_SUBMAP_CHAIN_H_

// Placing the submaps of one mapd log without roverd's log: each submap's
// SubmapInfo carries the frame switch that opened its frame (previous frame
// -> this one, x y z yaw), so the frames chain from the first submap's
// frame, which becomes the map frame. A frame whose switch starts in a frame
// no submap reached (mapd joined it half-way, or a frame without a submap
// lies in between) cannot be placed.

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "mapping/compose/submap_log.h"

namespace rover::host {

/// The switch SubmapInfo records as a transform: T_previous_frame.
Eigen::Isometry3d SubmapOriginTransform(const log::rover_msgs::SubmapInfo& info);

/// T_map_frame for every frame the submaps chain to; the first submap's
/// frame is the identity. The order of the submaps does not matter beyond
/// which one is first. Frames that do not chain are absent.
std::map<uint32_t, Eigen::Isometry3d> ChainSubmapOrigins(
    const std::vector<mapping::LoggedSubmap>& submaps);

/// Why `info`'s frame is not in `origins` (for the report), e.g. "no origin
/// recorded (mapd joined frame 4 half-way)".
std::string WhyUnplaced(const log::rover_msgs::SubmapInfo& info,
                        const std::map<uint32_t, Eigen::Isometry3d>& origins);

}  // namespace rover::host

#endif  // ROVER_HOST_LOG_SUBMAP_CHAIN_H_
