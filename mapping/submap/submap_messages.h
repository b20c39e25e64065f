#ifndef ROVER_MAPPING_SUBMAP_SUBMAP_MESSAGES_H_
#define ROVER_MAPPING_SUBMAP_SUBMAP_MESSAGES_H_

// A submap's octree and cloud as ROS messages, so they travel and are logged
// in standard form: octomap_msgs/Octomap (binary: the .bt body, the same
// bytes octomap_msgs::binaryMapToMsg writes) and sensor_msgs/PointCloud2
// with fields x, y, z (float32) and obstacle (uint8), 13 bytes per point.

#include <memory>
#include <string>

#include <octomap/OcTree.h>

#include "core/log/msgs/octomap_msgs.h"
#include "core/log/msgs/sensor_msgs.h"
#include "mapping/submap/cloud_point.h"

namespace rover::mapping {

/// The octree's occupied/free state (binary form), stamped with `header`.
log::octomap_msgs::Octomap ToOctomapMsg(const octomap::OcTree& tree,
                                        const log::std_msgs::Header& header);

/// The tree a binary Octomap message carries. Throws std::runtime_error
/// naming the problem (not binary, not an OcTree, bad resolution, data not
/// an octree stream).
std::unique_ptr<octomap::OcTree> FromOctomapMsg(const log::octomap_msgs::Octomap& msg);

/// The cloud as an unordered PointCloud2 (height 1).
log::sensor_msgs::PointCloud2 ToPointCloud2(const PointCloud& cloud,
                                            const log::std_msgs::Header& header);

/// The cloud of a PointCloud2 written by ToPointCloud2 (fields x, y, z
/// float32 and optionally obstacle uint8, little-endian). Throws
/// std::runtime_error naming what is missing or inconsistent.
PointCloud FromPointCloud2(const log::sensor_msgs::PointCloud2& msg);

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_SUBMAP_SUBMAP_MESSAGES_H_
