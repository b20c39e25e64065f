#include "mapping/compose/map_composer.h"

#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

namespace rover::mapping {
namespace {

using Clock = std::chrono::steady_clock;

double MillisecondsSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

std::string IdText(uint32_t submap_id) { return "submap id " + std::to_string(submap_id); }

// Checked on entry: a NaN origin would otherwise make every later
// composition throw.
void CheckFinite(const Eigen::Isometry3d& T_world_submap, const char* function,
                 uint32_t submap_id) {
  if (!T_world_submap.matrix().allFinite()) {
    throw std::invalid_argument(std::string(function) + ": " + IdText(submap_id) +
                                " has a non-finite origin");
  }
}

}  // namespace

void MapComposerOptions::Validate() const {
  if (!(std::isfinite(resolution_m) && resolution_m > 0.0)) {
    throw std::invalid_argument("MapComposerOptions.resolution_m: expected > 0, found " +
                                std::to_string(resolution_m));
  }
  // Below 0.5 and above it: free and occupied must both stay representable.
  if (!(clamping_min_probability > 0.0 && clamping_min_probability < 0.5)) {
    throw std::invalid_argument(
        "MapComposerOptions.clamping_min_probability: expected in (0, 0.5), found " +
        std::to_string(clamping_min_probability));
  }
  if (!(clamping_max_probability > 0.5 && clamping_max_probability < 1.0)) {
    throw std::invalid_argument(
        "MapComposerOptions.clamping_max_probability: expected in (0.5, 1), found " +
        std::to_string(clamping_max_probability));
  }
  if (!(std::isfinite(recompose_translation_m) && recompose_translation_m >= 0.0)) {
    throw std::invalid_argument(
        "MapComposerOptions.recompose_translation_m: expected >= 0, found " +
        std::to_string(recompose_translation_m));
  }
  if (!(recompose_rotation_rad >= 0.0 && recompose_rotation_rad <= 3.14159265358979323846)) {
    throw std::invalid_argument(
        "MapComposerOptions.recompose_rotation_rad: expected in [0, pi], found " +
        std::to_string(recompose_rotation_rad));
  }
  if (!(std::isfinite(cloud_resolution_m) && cloud_resolution_m >= 0.0)) {
    throw std::invalid_argument(
        "MapComposerOptions.cloud_resolution_m: expected >= 0 (0 keeps all points), found " +
        std::to_string(cloud_resolution_m));
  }
}

std::size_t MapComposer::VoxelKeyHash::operator()(const VoxelKey& k) const {
  // The usual spatial hash (Teschner et al. 2003) on the voxel indices.
  return static_cast<std::size_t>(k.x) * 73856093u ^ static_cast<std::size_t>(k.y) * 19349663u ^
         static_cast<std::size_t>(k.z) * 83492791u;
}

void MapComposer::VoxelAccumulator::Add(const Eigen::Vector3d& p_m, bool is_obstacle) {
  sum_m += p_m;
  ++count;
  obstacle = obstacle || is_obstacle;
}

void MapComposer::VoxelAccumulator::Add(const VoxelAccumulator& other) {
  sum_m += other.sum_m;
  count += other.count;
  obstacle = obstacle || other.obstacle;
}

CloudPoint MapComposer::VoxelAccumulator::Mean() const {
  CloudPoint point;
  point.p_submap_m = (sum_m / static_cast<double>(count)).cast<float>();
  point.obstacle = obstacle;
  return point;
}

MapComposer::MapComposer(const MapComposerOptions& options)
    : options_(options), tree_(options.resolution_m) {
  options_.Validate();
  tree_.setClampingThresMin(options_.clamping_min_probability);
  tree_.setClampingThresMax(options_.clamping_max_probability);
}

void MapComposer::SetSubmap(uint32_t submap_id, std::shared_ptr<const octomap::OcTree> octree,
                            std::shared_ptr<const PointCloud> cloud,
                            const Eigen::Isometry3d& T_world_submap) {
  if (!octree || !cloud) {
    throw std::invalid_argument("MapComposer::SetSubmap: " + IdText(submap_id) +
                                " has no octree or no cloud");
  }
  if (std::abs(octree->getResolution() - options_.resolution_m) > 1e-9 * options_.resolution_m) {
    throw std::invalid_argument("MapComposer::SetSubmap: " + IdText(submap_id) +
                                " has resolution " + std::to_string(octree->getResolution()) +
                                " m, expected MapComposerOptions.resolution_m " +
                                std::to_string(options_.resolution_m) + " m");
  }
  CheckFinite(T_world_submap, "MapComposer::SetSubmap", submap_id);
  // Here rather than halfway through a rebuild, which would then fail on
  // every call.
  CheckLeafSpans(*octree, ("MapComposer::SetSubmap: " + IdText(submap_id)).c_str());
  if (stats_.released_submaps > 0 && !tree_cache_.merged_origins.empty() &&
      submap_id <= tree_cache_.merged_origins.rbegin()->first) {
    throw std::logic_error("MapComposer::SetSubmap: " + IdText(submap_id) +
                           " would need a rebuild (at or below a merged id), but submaps "
                           "were released by MergeAndRelease()");
  }
  MarkReplaced(&tree_cache_, submap_id);
  MarkReplaced(&cloud_cache_, submap_id);
  submaps_[submap_id] = Submap{std::move(octree), std::move(cloud), T_world_submap};
}

void MapComposer::MarkReplaced(CacheState* cache, uint32_t submap_id) {
  if (cache->merged_origins.empty()) return;
  // A cached submap's data changes, or a new one sorts before cached ones:
  // appending would not give the id-order composition.
  if (submap_id <= cache->merged_origins.rbegin()->first) cache->dirty = true;
}

void MapComposer::SetOrigin(uint32_t submap_id, const Eigen::Isometry3d& T_world_submap) {
  auto it = submaps_.find(submap_id);
  if (it == submaps_.end()) {
    throw std::out_of_range("MapComposer::SetOrigin: unknown " + IdText(submap_id));
  }
  CheckFinite(T_world_submap, "MapComposer::SetOrigin", submap_id);
  bool moves[2] = {false, false};
  CacheState* caches[2] = {&tree_cache_, &cloud_cache_};
  for (int i = 0; i < 2; ++i) {
    const auto merged = caches[i]->merged_origins.find(submap_id);
    moves[i] = merged != caches[i]->merged_origins.end() &&
               MovedBeyondThreshold(merged->second, T_world_submap);
  }
  if (it->second.released && (moves[0] || moves[1])) {
    throw std::logic_error("MapComposer::SetOrigin: " + IdText(submap_id) +
                           " was released by MergeAndRelease() and cannot move beyond the "
                           "recompose thresholds");
  }
  it->second.T_world_submap = T_world_submap;
  for (int i = 0; i < 2; ++i) caches[i]->dirty = caches[i]->dirty || moves[i];
}

const Eigen::Isometry3d& MapComposer::Origin(uint32_t submap_id) const {
  auto it = submaps_.find(submap_id);
  if (it == submaps_.end()) {
    throw std::out_of_range("MapComposer::Origin: unknown " + IdText(submap_id));
  }
  return it->second.T_world_submap;
}

bool MapComposer::MovedBeyondThreshold(const Eigen::Isometry3d& from,
                                       const Eigen::Isometry3d& to) const {
  if ((to.translation() - from.translation()).norm() > options_.recompose_translation_m) {
    return true;
  }
  const Eigen::AngleAxisd delta(from.linear().transpose() * to.linear());
  return std::abs(delta.angle()) > options_.recompose_rotation_rad;
}

std::vector<uint32_t> MapComposer::PendingIds(const CacheState& cache) const {
  auto it = cache.merged_origins.empty()
                ? submaps_.begin()
                : submaps_.upper_bound(cache.merged_origins.rbegin()->first);
  std::vector<uint32_t> ids;
  for (; it != submaps_.end(); ++it) ids.push_back(it->first);
  return ids;
}

void MapComposer::RecordMergeStats(const OctreeMergeStats& merge) {
  stats_.pushed_leaves += merge.pushed_leaves;
  stats_.out_of_range_leaves += merge.out_of_range_leaves;
}

void MapComposer::CheckRebuildable(const char* function) const {
  if (stats_.released_submaps == 0) return;
  for (const auto& [id, submap] : submaps_) {
    if (submap.released) {
      throw std::logic_error(std::string(function) + ": a rebuild needs " + IdText(id) +
                             ", released by MergeAndRelease()");
    }
  }
}

void MapComposer::RebuildTree() {
  CheckRebuildable("MapComposer::Compose");
  current_undo_.clear();
  tree_.clear();
  tree_cache_.merged_origins.clear();
  for (const auto& [id, submap] : submaps_) {
    // Lazy: inner nodes once at the end, not along every voxel's path.
    RecordMergeStats(
        MergeOctree(*submap.octree, submap.T_world_submap, /*lazy_eval=*/true, &tree_));
    tree_cache_.merged_origins[id] = submap.T_world_submap;
  }
  tree_.updateInnerOccupancy();
  // Merged free space is mostly clamped alike: pruning saves much memory.
  tree_.prune();
  tree_cache_.dirty = false;
  ++stats_.recompositions;
}

void MapComposer::AppendTree() {
  for (uint32_t id : PendingIds(tree_cache_)) {
    const Submap& submap = submaps_.at(id);
    // Not lazy: updateInnerOccupancy() would walk the whole map for one
    // submap's worth of changes.
    RecordMergeStats(
        MergeOctree(*submap.octree, submap.T_world_submap, /*lazy_eval=*/false, &tree_));
    tree_cache_.merged_origins[id] = submap.T_world_submap;
    ++stats_.appended_submaps;
  }
}

void MapComposer::UpdateTree() {
  // A first composition is a rebuild too: lazy merging is faster for many.
  if (tree_cache_.dirty || (tree_cache_.merged_origins.empty() && !submaps_.empty())) {
    RebuildTree();
  } else {
    // Take the previous call's current submap out before the cache changes.
    UndoMerge(&current_undo_, &tree_);
    AppendTree();
  }
}

const octomap::OcTree& MapComposer::Compose(const CurrentSubmap* current) {
  const Clock::time_point start = Clock::now();
  UpdateTree();
  if (current != nullptr && current->octree != nullptr) {
    RecordMergeStats(MergeOctree(*current->octree, current->T_world_submap,
                                 /*lazy_eval=*/false, &tree_, &current_undo_));
  }
  stats_.last_compose_ms = MillisecondsSince(start);
  return tree_;
}

MapComposer::VoxelKey MapComposer::KeyOf(const Eigen::Vector3d& p_m) const {
  return {static_cast<int64_t>(std::floor(p_m.x() / options_.cloud_resolution_m)),
          static_cast<int64_t>(std::floor(p_m.y() / options_.cloud_resolution_m)),
          static_cast<int64_t>(std::floor(p_m.z() / options_.cloud_resolution_m))};
}

void MapComposer::AddCloudToCache(const PointCloud& cloud,
                                  const Eigen::Isometry3d& T_world_submap) {
  for (const CloudPoint& point : cloud) {
    const Eigen::Vector3d p_world_m = T_world_submap * point.p_submap_m.cast<double>();
    if (!p_world_m.allFinite()) continue;  // no voxel for it (and floor() of NaN is no key)
    if (options_.cloud_resolution_m == 0.0) {
      CloudPoint world;
      world.p_submap_m = p_world_m.cast<float>();
      world.obstacle = point.obstacle;
      cloud_points_.push_back(world);
      continue;
    }
    const auto [it, inserted] = cloud_index_.try_emplace(KeyOf(p_world_m), cloud_voxels_.size());
    if (inserted) cloud_voxels_.emplace_back();
    cloud_voxels_[it->second].Add(p_world_m, point.obstacle);
  }
}

void MapComposer::RebuildCloud() {
  CheckRebuildable("MapComposer::ComposedCloud");
  cloud_voxels_.clear();
  cloud_index_.clear();
  cloud_points_.clear();
  cloud_cache_.merged_origins.clear();
  for (const auto& [id, submap] : submaps_) {
    AddCloudToCache(*submap.cloud, submap.T_world_submap);
    cloud_cache_.merged_origins[id] = submap.T_world_submap;
  }
  cloud_cache_.dirty = false;
  ++stats_.cloud_recompositions;
}

void MapComposer::AppendCloud() {
  for (uint32_t id : PendingIds(cloud_cache_)) {
    const Submap& submap = submaps_.at(id);
    AddCloudToCache(*submap.cloud, submap.T_world_submap);
    cloud_cache_.merged_origins[id] = submap.T_world_submap;
  }
}

void MapComposer::UpdateCloud() {
  if (cloud_cache_.dirty || (cloud_cache_.merged_origins.empty() && !submaps_.empty())) {
    RebuildCloud();
  } else {
    AppendCloud();
  }
}

void MapComposer::MergeAndRelease() {
  UpdateTree();
  UpdateCloud();
  for (auto& [id, submap] : submaps_) {
    if (submap.released) continue;
    submap.octree.reset();
    submap.cloud.reset();
    submap.released = true;
    ++stats_.released_submaps;
  }
}

PointCloud MapComposer::ComposedCloud(const CurrentSubmap* current) {
  const Clock::time_point start = Clock::now();
  UpdateCloud();
  const PointCloud* current_cloud =
      current != nullptr && current->cloud != nullptr ? current->cloud : nullptr;
  PointCloud out;
  if (options_.cloud_resolution_m == 0.0) {
    out.reserve(cloud_points_.size() + (current_cloud ? current_cloud->size() : 0));
    out.insert(out.end(), cloud_points_.begin(), cloud_points_.end());
    if (current_cloud != nullptr) {
      for (const CloudPoint& point : *current_cloud) {
        CloudPoint world;
        world.p_submap_m =
            (current->T_world_submap * point.p_submap_m.cast<double>()).cast<float>();
        world.obstacle = point.obstacle;
        out.push_back(world);
      }
    }
    stats_.last_cloud_ms = MillisecondsSince(start);
    return out;
  }
  // The current cloud's share kept apart, so that the cache stays clean:
  // additions to cached voxels by index, new voxels in their own list.
  std::unordered_map<std::size_t, VoxelAccumulator> added_to_cached;
  std::vector<VoxelAccumulator> new_voxels;
  std::unordered_map<VoxelKey, std::size_t, VoxelKeyHash> new_index;
  if (current_cloud != nullptr) {
    for (const CloudPoint& point : *current_cloud) {
      const Eigen::Vector3d p_world_m = current->T_world_submap * point.p_submap_m.cast<double>();
      if (!p_world_m.allFinite()) continue;
      const VoxelKey key = KeyOf(p_world_m);
      if (auto cached = cloud_index_.find(key); cached != cloud_index_.end()) {
        added_to_cached[cached->second].Add(p_world_m, point.obstacle);
        continue;
      }
      const auto [it, inserted] = new_index.try_emplace(key, new_voxels.size());
      if (inserted) new_voxels.emplace_back();
      new_voxels[it->second].Add(p_world_m, point.obstacle);
    }
  }
  out.reserve(cloud_voxels_.size() + new_voxels.size());
  for (std::size_t i = 0; i < cloud_voxels_.size(); ++i) {
    auto added = added_to_cached.find(i);
    if (added == added_to_cached.end()) {
      out.push_back(cloud_voxels_[i].Mean());
    } else {
      VoxelAccumulator merged = cloud_voxels_[i];
      merged.Add(added->second);
      out.push_back(merged.Mean());
    }
  }
  for (const VoxelAccumulator& voxel : new_voxels) out.push_back(voxel.Mean());
  stats_.last_cloud_ms = MillisecondsSince(start);
  return out;
}

MapComposerStats MapComposer::Stats() const {
  MapComposerStats stats = stats_;
  stats.submaps = submaps_.size();
  stats.composed_leaves = tree_.getNumLeafNodes();
  stats.octree_memory_bytes = tree_.memoryUsage() + current_undo_.capacity() * sizeof(VoxelUndo);
  // Hash nodes approximated as key + index + next pointer.
  stats.cloud_memory_bytes =
      cloud_voxels_.capacity() * sizeof(VoxelAccumulator) +
      cloud_index_.size() * (sizeof(VoxelKey) + sizeof(std::size_t) + sizeof(void*)) +
      cloud_index_.bucket_count() * sizeof(void*) + cloud_points_.capacity() * sizeof(CloudPoint);
  return stats;
}

}  // namespace rover::mapping
