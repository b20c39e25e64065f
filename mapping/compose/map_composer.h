#ifndef ROVER_MAPPING_COMPOSE_MAP_COMPOSER_H_
#define ROVER_MAPPING_COMPOSE_MAP_COMPOSER_H_

// The global map (thesis section 5.2.2): all submaps placed at the latest
// optimised origins of their frames (from the pose graph) and merged, the
// probabilistic voxels by summing log-odds with clamping (octree_merge.h),
// the point clouds by concatenating and voxel-filtering them back to their
// own resolution.
//
// Merging all submaps is expensive and grows with their number, so the
// composition of the finished submaps is cached. A newly finished submap is
// merged into the cache as it comes; the cache is rebuilt from scratch only
// when a submap is replaced or an origin it was built with moves by more
// than a threshold (a significant loop closure), so the many small
// corrections of every optimisation cost nothing. The current, still growing
// submap is never cached: it is merged fresh on every call, so the map is
// always up to date with the rover's own latest data.
//
// The composed octree is kept in one tree. Rather than copying the cached
// tree for every call (O(map)), each call undoes the previous call's
// current-submap updates from a log of the voxels' prior states and merges
// the new current submap (O(current submap)); this also saves a second
// tree's memory. Measured on the dev machine, 30 yawed 8 m submaps (0.57M
// composed leaves, 23 MB): rebuild 330 ms, a plain copy of the tree 54 ms,
// undo + merge of a 27k-voxel current submap 22 ms. The copy grows with the
// map, the undo does not. As updates go in submap id order either way, the
// voxels are the same as composing from scratch.
//
// Not thread-safe: the thesis composes in its own thread; the owner
// serialises calls.

#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <unordered_map>
#include <vector>

#include <octomap/OcTree.h>
#include <Eigen/Geometry>

#include "mapping/compose/octree_merge.h"
#include "mapping/submap/cloud_point.h"

namespace rover::mapping {

struct MapComposerOptions {
  /// Voxel edge of the composed octree; every submap octree must share it.
  double resolution_m = 0.1;
  /// Clamping of the composed log-odds sums, as probabilities (those of the
  /// submaps, so that merged voxels stay as easy to change as measured ones).
  double clamping_min_probability = 0.12;
  double clamping_max_probability = 0.97;
  /// A cached submap origin moving by more than this rebuilds the cache:
  /// about half a voxel, below which voxels would hardly change.
  double recompose_translation_m = 0.05;
  /// Likewise for the rotation angle (0.5 deg).
  double recompose_rotation_rad = 0.5 * 3.14159265358979323846 / 180.0;
  /// Voxel edge of the filter that thins merged point clouds where submaps
  /// overlap (the submaps' own cloud resolution); 0 keeps every point.
  double cloud_resolution_m = 0.05;

  /// Throws std::invalid_argument "MapComposerOptions.<key>: ...".
  void Validate() const;
};

/// The submap being built: merged fresh on every call, never cached. Either
/// pointer may be null (that representation is then not merged); pointees
/// must stay valid for the call only.
struct CurrentSubmap {
  const octomap::OcTree* octree = nullptr;
  const PointCloud* cloud = nullptr;
  Eigen::Isometry3d T_world_submap = Eigen::Isometry3d::Identity();
};

struct MapComposerStats {
  /// Full rebuilds of the cached octree composition (the first one included).
  uint64_t recompositions = 0;
  /// Finished submaps merged into the cached octree without a rebuild.
  uint64_t appended_submaps = 0;
  /// Wall time of the last Compose() call, current submap included.
  double last_compose_ms = 0.0;
  /// The same for the point cloud cache and ComposedCloud().
  uint64_t cloud_recompositions = 0;
  double last_cloud_ms = 0.0;
  /// Finished submaps held (released ones included).
  std::size_t submaps = 0;
  /// Of those, released by MergeAndRelease(): only their origin is held.
  std::size_t released_submaps = 0;
  /// Leaves of the composed octree as last returned by Compose().
  std::size_t composed_leaves = 0;
  /// Approximate memory of the composed octree and the cloud cache.
  std::size_t octree_memory_bytes = 0;
  std::size_t cloud_memory_bytes = 0;
  /// Occupied submap leaves no composed voxel centre sampled, pushed to the
  /// voxel holding their centre instead (see octree_merge.h).
  uint64_t pushed_leaves = 0;
  /// Submap leaves dropped for landing outside the composed tree's range.
  uint64_t out_of_range_leaves = 0;
};

class MapComposer {
 public:
  /// Throws std::invalid_argument if `options` are invalid.
  explicit MapComposer(const MapComposerOptions& options = MapComposerOptions());
  MapComposer(const MapComposer&) = delete;
  MapComposer& operator=(const MapComposer&) = delete;

  /// Adds a finished submap, or replaces one with the same id. Both
  /// pointers must be non-null, the octree at the options' resolution with
  /// no absurdly coarse leaf, and the origin finite (std::invalid_argument
  /// otherwise, naming the id). The composer shares, and never modifies, the
  /// data. A new id above all cached ones is appended to the cache at the
  /// next call; a replacement, or an id below a cached one, rebuilds the
  /// cache (merge order decides where clamping bites, and the cache must
  /// equal a composition in id order).
  void SetSubmap(uint32_t submap_id, std::shared_ptr<const octomap::OcTree> octree,
                 std::shared_ptr<const PointCloud> cloud, const Eigen::Isometry3d& T_world_submap);

  /// The pose graph moved a submap's origin. The new origin is used by the
  /// next rebuild; it triggers one only if it differs from the origin the
  /// cache holds that submap at by more than the recompose thresholds.
  /// Throws std::out_of_range naming the id if the submap is unknown,
  /// std::invalid_argument if the origin is not finite.
  void SetOrigin(uint32_t submap_id, const Eigen::Isometry3d& T_world_submap);

  /// Whether a finished submap with this id was set.
  bool HasSubmap(uint32_t submap_id) const { return submaps_.count(submap_id) > 0; }
  /// Latest origin set for a submap; std::out_of_range if unknown.
  const Eigen::Isometry3d& Origin(uint32_t submap_id) const;

  /// The composed octree: the cached composition of the finished submaps
  /// (brought up to date first) plus `current`, if given, merged fresh. The
  /// reference stays valid, and unchanged, until the next non-const call.
  /// Throws std::invalid_argument if the current octree's resolution differs.
  const octomap::OcTree& Compose(const CurrentSubmap* current = nullptr);

  /// The composed point cloud in the world frame: every submap cloud placed
  /// at its origin, `current`'s included, voxel-filtered to
  /// cloud_resolution_m (each voxel gives the mean of its points, flagged as
  /// an obstacle if any of them was). CloudPoint::p_submap_m holds world
  /// coordinates here; non-finite points are dropped. Points come in a
  /// deterministic order (voxels in order of first appearance, submaps in id
  /// order, current last).
  PointCloud ComposedCloud(const CurrentSubmap* current = nullptr);

  /// Merges every submap set so far into the cached octree and point cloud
  /// and drops the composer's share of their data, keeping only their
  /// origins. This composes submaps whose origins are final (a finished
  /// log) in one pass, in memory that grows with the map's extent rather
  /// than with the number of submaps. A released submap cannot be merged
  /// again: SetOrigin() moving one beyond the recompose thresholds, or
  /// SetSubmap() with an id at or below a merged one, then throws
  /// std::logic_error naming the id.
  void MergeAndRelease();

  /// Counters and sizes; counting leaves walks the tree (O(map)).
  MapComposerStats Stats() const;

  /// The options the composer was built with.
  const MapComposerOptions& options() const { return options_; }

 private:
  struct Submap {
    std::shared_ptr<const octomap::OcTree> octree;
    std::shared_ptr<const PointCloud> cloud;
    Eigen::Isometry3d T_world_submap = Eigen::Isometry3d::Identity();
    bool released = false;  ///< data dropped by MergeAndRelease()
  };

  // What one cache (octree or cloud) holds: each merged submap's origin at
  // merge time, which SetOrigin compares against.
  struct CacheState {
    std::map<uint32_t, Eigen::Isometry3d> merged_origins;
    bool dirty = false;
  };

  struct VoxelKey {
    int64_t x = 0;
    int64_t y = 0;
    int64_t z = 0;
    bool operator==(const VoxelKey&) const = default;
  };
  struct VoxelKeyHash {
    std::size_t operator()(const VoxelKey& k) const;
  };
  struct VoxelAccumulator {
    Eigen::Vector3d sum_m = Eigen::Vector3d::Zero();
    uint32_t count = 0;
    bool obstacle = false;
    void Add(const Eigen::Vector3d& p_m, bool is_obstacle);
    void Add(const VoxelAccumulator& other);
    CloudPoint Mean() const;
  };

  bool MovedBeyondThreshold(const Eigen::Isometry3d& from, const Eigen::Isometry3d& to) const;
  void MarkReplaced(CacheState* cache, uint32_t submap_id);
  // Submaps not yet in a cache whose ids are above all cached ones.
  std::vector<uint32_t> PendingIds(const CacheState& cache) const;

  void RebuildTree();
  void AppendTree();
  void RecordMergeStats(const OctreeMergeStats& merge);

  // Brings a cache up to date with the finished submaps (rebuild or append).
  void UpdateTree();
  void UpdateCloud();
  // Throws std::logic_error if a rebuild would need a released submap.
  void CheckRebuildable(const char* function) const;

  void RebuildCloud();
  void AppendCloud();
  void AddCloudToCache(const PointCloud& cloud, const Eigen::Isometry3d& T_world_submap);
  VoxelKey KeyOf(const Eigen::Vector3d& p_m) const;

  MapComposerOptions options_;
  std::map<uint32_t, Submap> submaps_;  // ordered: merges go in id order

  CacheState tree_cache_;
  // The cached composition, plus the last current submap until undone.
  octomap::OcTree tree_;
  // Prior states of the voxels the last current submap changed.
  std::vector<VoxelUndo> current_undo_;

  CacheState cloud_cache_;
  // cloud_resolution_m > 0: voxels in order of first appearance.
  std::vector<VoxelAccumulator> cloud_voxels_;
  std::unordered_map<VoxelKey, std::size_t, VoxelKeyHash> cloud_index_;
  // cloud_resolution_m == 0: all points, world frame.
  PointCloud cloud_points_;

  MapComposerStats stats_;
};

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_COMPOSE_MAP_COMPOSER_H_
