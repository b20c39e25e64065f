#ifndef ROVER_MAPPING_SUBMAP_SUBMAP_H_
#define ROVER_MAPPING_SUBMAP_SUBMAP_H_

// One submap (thesis section 5.1.2): the depth images and obstacle
// classifications of one stretch of the drive, aggregated along the local
// reference filter's poses into the submap's own frame. Each submap starts
// with a frame switch of the filter, so its frame is the filter's local
// frame of that moment: gravity-aligned, origin at the switch. It holds
// both representations: a probabilistic OctoMap voxel space (10 cm) and a
// voxel-filtered point cloud with obstacle flags (5 cm). Once finished it
// does not change; it is then pruned and sent to the other robots once.

#include <cstdint>
#include <memory>
#include <vector>

#include <octomap/OcTree.h>
#include <Eigen/Geometry>

#include "mapping/depth/depth_image.h"
#include "mapping/submap/cloud_point.h"
#include "mapping/submap/fast_octree_inserter.h"
#include "mapping/submap/submap_options.h"
#include "mapping/submap/voxel_centroid_cloud.h"

namespace rover::mapping {

class Submap {
 public:
  /// `index` counts the robot's submaps; `frame_id` names the filter's
  /// local frame the submap lives in. Throws std::invalid_argument for
  /// invalid options.
  Submap(uint32_t index, uint32_t frame_id, const SubmapOptions& options);

  /// Adds one depth image taken at T_submap_cam: its beams into the voxel
  /// space (see FastOctreeInserter), its kValid points (within
  /// max_range_m, if set) into the cloud. `obstacle_mask` holds one byte
  /// per pixel, row-major, nonzero for obstacles; empty means none.
  /// Throws std::logic_error after Finish(), std::invalid_argument for a
  /// mask of the wrong size or a camera outside the octree's range.
  void Integrate(const DepthImage& depth, const std::vector<uint8_t>& obstacle_mask,
                 const Eigen::Isometry3d& T_submap_cam);

  /// Prunes the voxel space (identical children merged, which clamping
  /// makes frequent) and freezes the submap.
  void Finish();

  /// The submap's number among the robot's submaps.
  uint32_t index() const { return index_; }
  /// The filter's local frame the submap lives in.
  uint32_t frame_id() const { return frame_id_; }
  /// The options it was made with.
  const SubmapOptions& options() const { return options_; }
  /// True after Finish(): the submap no longer changes.
  bool finished() const { return finished_; }
  /// Depth images integrated so far.
  int images() const { return images_; }
  /// The voxel space, in the submap frame.
  const octomap::OcTree& octree() const { return *tree_; }
  /// The point cloud (computed on each call: one centroid per voxel).
  PointCloud cloud() const { return cloud_.Points(); }
  /// Non-empty cloud voxels, without computing the cloud.
  std::size_t cloud_size() const { return cloud_.size(); }
  /// Figures of the last image's voxel-space insertion.
  const FastOctreeInserterStats& last_insertion() const { return inserter_.stats(); }

 private:
  uint32_t index_ = 0;
  uint32_t frame_id_ = 0;
  SubmapOptions options_;
  std::unique_ptr<octomap::OcTree> tree_;
  FastOctreeInserter inserter_;
  VoxelCentroidCloud cloud_;
  int images_ = 0;
  bool finished_ = false;
};

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_SUBMAP_SUBMAP_H_
