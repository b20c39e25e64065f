#ifndef ROVER_MAPPING_SUBMAP_VOXEL_CENTROID_CLOUD_H_
#define ROVER_MAPPING_SUBMAP_VOXEL_CENTROID_CLOUD_H_

// The point cloud of a submap (thesis section 5.1.2): a voxel grid (5 cm)
// keeps, per non-empty voxel, the centroid of all points that fell into it
// (a better surface estimate than the voxel centre) and an obstacle flag set
// if any of them was an obstacle. The thesis filters each image and then the
// accumulated cloud again with the same grid; accumulating every point's sum
// in one grid gives the same voxels with the exact mean of all their points
// (rather than a mean of per-image means).

#include <cstddef>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "mapping/submap/cloud_point.h"

namespace rover::mapping {

class VoxelCentroidCloud {
 public:
  /// Throws std::invalid_argument unless resolution_m is finite and > 0.
  explicit VoxelCentroidCloud(double resolution_m = 0.05);

  /// Adds a point in the submap frame. Returns false, adding nothing, for a
  /// non-finite point or one beyond +-2^20 voxels (52 km at 5 cm).
  bool Add(const Eigen::Vector3f& p_submap_m, bool obstacle);

  /// One point per voxel: the centroid, and the OR of the obstacle flags.
  /// Sorted by voxel index (z, then y, then x), so equal inputs give equal
  /// clouds whatever the order of the points.
  PointCloud Points() const;

  /// Non-empty voxels.
  std::size_t size() const { return voxels_.size(); }
  /// Voxel edge.
  double resolution_m() const { return resolution_m_; }
  /// Forgets all points, keeping the memory.
  void Clear();

 private:
  struct Voxel {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();  // double: exact for many float points
    uint32_t count = 0;
    bool obstacle = false;
    uint64_t key = 0;
  };

  std::size_t Find(uint64_t key);
  void Grow();

  double resolution_m_ = 0.05;
  std::vector<Voxel> voxels_;
  /// Open addressing: key + 1 (0: empty) and the voxel's index.
  std::vector<uint64_t> slot_keys_;
  std::vector<uint32_t> slot_index_;
  std::size_t mask_ = 0;
  /// Neighbouring pixels mostly fall into the voxel of the previous one.
  uint64_t last_key_ = 0;
  std::size_t last_index_ = 0;
  bool has_last_ = false;
};

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_SUBMAP_VOXEL_CENTROID_CLOUD_H_
