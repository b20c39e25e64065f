#ifndef ROVER_MAPPING_SUBMAP_CLOUD_POINT_H_
#define ROVER_MAPPING_SUBMAP_CLOUD_POINT_H_

// One point of a submap's point cloud: the centroid of the depth points that
// fell into one cloud voxel (5 cm), in the submap's frame, and whether the
// obstacle classification flagged it. Shared by mapping/submap (which builds
// clouds) and mapping/compose (which places them in the global map).

#include <vector>

#include <Eigen/Core>

namespace rover::mapping {

struct CloudPoint {
  Eigen::Vector3f p_submap_m = Eigen::Vector3f::Zero();
  /// Set when at least one depth point of the voxel lay on an obstacle
  /// (a step above h_max + Delta_d, or a negative edge).
  bool obstacle = false;
};

using PointCloud = std::vector<CloudPoint>;

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_SUBMAP_CLOUD_POINT_H_
