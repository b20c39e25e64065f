#ifndef ROVER_MAPPING_TEAM_TEAM_SUBMAP_H_
#define ROVER_MAPPING_TEAM_TEAM_SUBMAP_H_

// A finished submap as it travels to the other rovers: the three messages
// mapd logs for it (rover_msgs/SubmapInfo, octomap_msgs/Octomap and
// sensor_msgs/PointCloud2), compressed together with zstd, sent once. The
// info and octree travel as their CDR; the cloud, which is most of a
// submap, as its points quantised to 1 mm (they are centroids of 5 cm
// voxels), delta-coded and split into byte planes, which zstd compresses to
// a fraction of the float bytes. The receiver gets what the sender logged,
// the cloud to the millimetre, so it can match the submap against its own,
// compose the team's map, and log it in the same form.

#include <cstdint>
#include <span>
#include <vector>

#include "core/log/msgs/octomap_msgs.h"
#include "core/log/msgs/rover_msgs.h"
#include "core/log/msgs/sensor_msgs.h"

namespace rover::mapping {

struct TeamSubmap {
  log::rover_msgs::SubmapInfo info;
  log::octomap_msgs::Octomap octomap;
  /// mapd's cloud layout (mapping::ToPointCloud2, the header of `info`).
  log::sensor_msgs::PointCloud2 cloud;
};

/// Largest decompressed submap accepted (a hostile size field cannot make a
/// rover allocate more).
inline constexpr std::size_t kMaxTeamSubmapBytes = std::size_t{64} << 20;

/// zstd at `level` (1..19) over the three messages' CDR.
std::vector<uint8_t> EncodeSubmap(const TeamSubmap& submap, int level = 9);
/// Throws TeamMessageError (team_message.h) for another version or kind, a
/// size over kMaxTeamSubmapBytes, a zstd frame that does not decompress to
/// the size it states, or messages that do not decode, naming which.
TeamSubmap DecodeSubmap(std::span<const uint8_t> bytes);

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_TEAM_TEAM_SUBMAP_H_
