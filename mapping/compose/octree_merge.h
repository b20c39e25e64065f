#ifndef ROVER_MAPPING_COMPOSE_OCTREE_MERGE_H_
#define ROVER_MAPPING_COMPOSE_OCTREE_MERGE_H_

// Merging one submap octree into the global one (thesis section 5.2.2): every
// voxel's log-odds is added to the global voxel it lands on, and the global
// tree clamps the sum (OccupancyOcTreeBase::updateNodeLogOdds adds, then
// clamps to [clamping_thres_min, clamping_thres_max]), which is the same as a
// measurement update of that voxel.
//
// Which global voxel a submap voxel lands on: the two grids differ by a rigid
// motion, so voxels do not map one to one. Pushing each submap voxel centre
// through T_world_submap and taking the voxel it falls into aliases under
// rotation (yaw is arbitrary: submaps start at the rover's heading): some
// global voxels receive two submap voxels (their log-odds counted twice) and
// others none (holes in free space and in ground surfaces). We sample
// instead: each global voxel whose centre, taken back into the submap frame,
// lies in a known submap voxel receives that voxel's log-odds, once. That
// leaves no holes and counts nothing twice. Sampling can miss an isolated
// voxel whose rotated cube happens to contain no global centre; an occupied
// one is then pushed to the voxel holding its centre, so that no obstacle is
// ever lost (that voxel may then count twice; missed free voxels are
// dropped). The thesis interpolates trilinearly (Jessup et al. 2015), which
// also smooths; nearest-voxel sampling keeps thin obstacles sharp and costs
// about as much as pushing. For grid-aligned motions (whole-voxel
// translations, yaw in multiples of 90 deg) both rules give the same map.
//
// A pruned leaf above the finest depth stands for all the finest voxels it
// contains and is sampled as such.

#include <cstddef>
#include <vector>

#include <octomap/OcTree.h>
#include <Eigen/Geometry>

namespace rover::mapping {

/// A voxel's state before a merge changed it, so that the change can be
/// taken back (see UndoMerge).
struct VoxelUndo {
  octomap::OcTreeKey key;
  bool existed = false;   ///< false: the voxel was unknown
  float log_odds = 0.0f;  ///< previous value where it existed
};

struct OctreeMergeStats {
  /// Global voxel updates made (one per sampled or pushed voxel).
  std::size_t voxels_updated = 0;
  /// Occupied submap leaves no global centre sampled, pushed instead.
  std::size_t pushed_leaves = 0;
  /// Submap leaves skipped because they would land outside the global tree's
  /// key range (+-2^15 voxels around its origin).
  std::size_t out_of_range_leaves = 0;
};

/// Leaves coarser than this many finest voxels per edge are rejected: no
/// submap (tens of metres) holds a fully known cube that large, so such a
/// leaf means a corrupt tree, and expanding it would take hours.
inline constexpr unsigned kMaxLeafSpanVoxels = 256;

/// Throws std::invalid_argument (prefixed with `what`) if any leaf of `tree`
/// spans more than kMaxLeafSpanVoxels finest voxels per edge.
void CheckLeafSpans(const octomap::OcTree& tree, const char* what);

/// Adds every leaf of `source`, placed by `T_target_source`, into `target` by
/// summing log-odds with the target's clamping (see the file comment for the
/// voxel correspondence). With `lazy_eval` inner nodes are left stale and the
/// caller must call target->updateInnerOccupancy() afterwards (cheaper for
/// large merges into a growing tree); without, every update keeps its path
/// consistent and prunes (cheaper for small merges into a large tree). When
/// `undo` is given, each voxel's previous state is appended before it is
/// changed. Throws std::invalid_argument if the resolutions differ, the
/// transform is not finite, or a leaf is too coarse (CheckLeafSpans); updates made before the throw
/// stay (and are in `undo`).
OctreeMergeStats MergeOctree(const octomap::OcTree& source,
                             const Eigen::Isometry3d& T_target_source, bool lazy_eval,
                             octomap::OcTree* target, std::vector<VoxelUndo>* undo = nullptr);

/// Restores the voxels recorded in `undo` (newest first, so a voxel updated
/// twice gets its oldest state back), then clears `undo`. Leaves `target`
/// with consistent inner nodes.
void UndoMerge(std::vector<VoxelUndo>* undo, octomap::OcTree* target);

/// Removes the finest voxel at `key` (expanding a pruned leaf holding it) and
/// any inner nodes left without children; false if it was unknown.
/// OcTree::deleteNode cannot be used for this: in octomap 1.9.x it deletes a
/// node whose child array is still allocated when that node loses its last
/// child, which trips an assertion and leaks (OctoMap issue #287), and it
/// keeps a childless root that then reads as one huge known voxel (#307).
bool DeleteVoxel(const octomap::OcTreeKey& key, octomap::OcTree* tree);

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_COMPOSE_OCTREE_MERGE_H_
