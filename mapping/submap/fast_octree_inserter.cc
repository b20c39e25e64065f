#include "mapping/submap/fast_octree_inserter.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cstdlib>
#include <stdexcept>
#include <string>

namespace rover::mapping {
namespace {

// Flags per voxel of one image.
constexpr uint8_t kHit = 1;        // holds an endpoint: updated as occupied
constexpr uint8_t kRayEnd = 2;     // a ray is cast to its centre
constexpr uint8_t kTraversed = 4;  // a ray passed through: free unless a hit

constexpr int kTreeDepth = 16;  // OctoMap's fixed depth (16-bit keys)

uint64_t Pack(const octomap::OcTreeKey& k) {
  return uint64_t{k[0]} | (uint64_t{k[1]} << 16) | (uint64_t{k[2]} << 32);
}

octomap::OcTreeKey Unpack(uint64_t p) {
  return {static_cast<octomap::key_type>(p & 0xffff),
          static_cast<octomap::key_type>((p >> 16) & 0xffff),
          static_cast<octomap::key_type>((p >> 32) & 0xffff)};
}

// Bit i of a 16-bit value to bit 3i.
uint64_t Spread3(uint64_t x) {
  x &= 0xffff;
  x = (x | (x << 16)) & 0x001f'0000'ff00'00ffull;
  x = (x | (x << 8)) & 0x100f'00f0'0f00'f00full;
  x = (x | (x << 4)) & 0x10c3'0c30'c30c'30c3ull;
  x = (x | (x << 2)) & 0x1249'2492'4924'9249ull;
  return x;
}

// Inverse of Spread3.
uint64_t Compact3(uint64_t x) {
  x &= 0x1249'2492'4924'9249ull;
  x = (x ^ (x >> 2)) & 0x10c3'0c30'c30c'30c3ull;
  x = (x ^ (x >> 4)) & 0x100f'00f0'0f00'f00full;
  x = (x ^ (x >> 8)) & 0x001f'0000'ff00'00ffull;
  x = (x ^ (x >> 16)) & 0x001f'0000'0000'ffffull;
  x = (x ^ (x >> 32)) & 0xffff;
  return x;
}

// Interleaved so that the three bits of one octree level are adjacent and
// ordered like OctoMap's child index (x: 1, y: 2, z: 4), the root's first:
// ascending codes visit the leaves depth first.
uint64_t MortonOfPacked(uint64_t p) {
  return Spread3(p & 0xffff) | (Spread3((p >> 16) & 0xffff) << 1) |
         (Spread3((p >> 32) & 0xffff) << 2);
}

octomap::OcTreeKey KeyOfMorton(uint64_t m) {
  return {static_cast<octomap::key_type>(Compact3(m)),
          static_cast<octomap::key_type>(Compact3(m >> 1)),
          static_cast<octomap::key_type>(Compact3(m >> 2))};
}

// OctoMap's coordToKeyChecked for one axis, inline: floor(factor * c) +
// 2^15 in [0, 2^16), with the same double arithmetic (so the same keys at
// voxel borders) but without a libm floor call per pixel. Also the point's
// ray cell along the axis, 0..cells - 1.
[[gnu::always_inline]] inline bool AxisKey(float c, double resolution_factor, int cells,
                                           octomap::key_type* key, unsigned* cell) {
  const double a = resolution_factor * static_cast<double>(c);
  if (!(a >= -32768.0 && a < 32768.0)) return false;  // also NaN
  int i = static_cast<int>(a);
  if (static_cast<double>(i) > a) --i;  // truncation to floor
  *key = static_cast<octomap::key_type>(i + 32768);
  *cell = static_cast<unsigned>(std::min(static_cast<int>((a - i) * cells), cells - 1));
  return true;
}

// The voxel key of p and its ray cell index (x + n (y + n z)).
[[gnu::always_inline]] inline bool KeyOf(const octomap::point3d& p, double resolution_factor,
                                         int cells, octomap::OcTreeKey* key, unsigned* cell) {
  unsigned cx = 0, cy = 0, cz = 0;
  if (!AxisKey(p.x(), resolution_factor, cells, &(*key)[0], &cx) ||
      !AxisKey(p.y(), resolution_factor, cells, &(*key)[1], &cy) ||
      !AxisKey(p.z(), resolution_factor, cells, &(*key)[2], &cz)) {
    return false;
  }
  const auto n = static_cast<unsigned>(cells);
  *cell = cx + n * (cy + n * cz);
  return true;
}

// LSD radix sort of values below 2^52, 13 bits per pass; `scratch` and
// `counts` are reused buffers.
void RadixSort(std::vector<uint64_t>& values, std::vector<uint64_t>& scratch,
               std::vector<uint32_t>& counts) {
  constexpr int kBits = 13;
  constexpr std::size_t kBuckets = std::size_t{1} << kBits;
  scratch.resize(values.size());
  counts.resize(kBuckets);
  for (int shift = 0; shift < 4 * kBits; shift += kBits) {
    std::fill(counts.begin(), counts.end(), 0u);
    for (const uint64_t v : values) ++counts[(v >> shift) & (kBuckets - 1)];
    uint32_t sum = 0;
    for (uint32_t& c : counts) {
      const uint32_t n = c;
      c = sum;
      sum += n;
    }
    for (const uint64_t v : values) scratch[counts[(v >> shift) & (kBuckets - 1)]++] = v;
    values.swap(scratch);
  }
}

}  // namespace

FastOctreeInserter::FastOctreeInserter(const SubmapOptions& options) : options_(options) {
  options_.Validate();
  const auto n = static_cast<std::size_t>(options_.ray_cells_per_voxel_edge);
  cells_per_voxel_ = n * n * n;
}

void FastOctreeInserter::Insert(const DepthImage& depth, const Eigen::Isometry3d& T_submap_cam,
                                octomap::OcTree* tree) {
  if (tree == nullptr) throw std::invalid_argument("FastOctreeInserter: null tree");
  const Eigen::Vector3d origin = T_submap_cam.translation();
  Begin(origin, *tree);
  const Eigen::Matrix3d R = T_submap_cam.linear();
  const double free_range = options_.max_free_range_m;
  for (int v = 0; v < depth.height(); ++v) {
    for (int u = 0; u < depth.width(); ++u) {
      switch (depth.state(u, v)) {
        case DepthState::kValid:
          AddHit(T_submap_cam * depth.point(u, v).cast<double>());
          break;
        case DepthState::kInfinite:
          if (free_range > 0.0) {
            const Eigen::Vector3d end = origin + free_range * (R * depth.Ray(u, v).normalized());
            AddFreeEnd(octomap::point3d(static_cast<float>(end.x()), static_cast<float>(end.y()),
                                        static_cast<float>(end.z())));
          }
          break;
        case DepthState::kInvalid:
        case DepthState::kUncertain:
          break;
      }
    }
  }
  CastRays(*tree);
  UpdateTree(tree);
}

void FastOctreeInserter::InsertScan(std::span<const Eigen::Vector3d> hits,
                                    std::span<const Eigen::Vector3d> free_ends,
                                    const Eigen::Vector3d& origin, octomap::OcTree* tree) {
  if (tree == nullptr) throw std::invalid_argument("FastOctreeInserter: null tree");
  Begin(origin, *tree);
  for (const Eigen::Vector3d& p : hits) AddHit(p);
  for (const Eigen::Vector3d& e : free_ends) {
    if (!e.allFinite()) {
      ++stats_.skipped_points;
      continue;
    }
    AddFreeEnd(octomap::point3d(static_cast<float>(e.x()), static_cast<float>(e.y()),
                                static_cast<float>(e.z())));
  }
  CastRays(*tree);
  UpdateTree(tree);
}

void FastOctreeInserter::Begin(const Eigen::Vector3d& origin, const octomap::OcTree& tree) {
  origin_ = octomap::point3d(static_cast<float>(origin.x()), static_cast<float>(origin.y()),
                             static_cast<float>(origin.z()));
  resolution_factor_ = 1.0 / tree.getResolution();  // as OctoMap computes it
  if (!origin.allFinite() || !tree.coordToKeyChecked(origin_, origin_key_)) {
    throw std::invalid_argument("FastOctreeInserter: sensor origin (" + std::to_string(origin.x()) +
                                ", " + std::to_string(origin.y()) + ", " +
                                std::to_string(origin.z()) + ") outside the octree's key range");
  }
  stats_ = {};
  table_.Clear();
  targets_.clear();
  last_tagged_key_ = ~uint64_t{0};
}

void FastOctreeInserter::AddHit(const Eigen::Vector3d& p) {
  if (!p.allFinite()) {
    ++stats_.skipped_points;
    return;
  }
  // In float, as insertPointCloud sees an octomap::Pointcloud: the same
  // keys at voxel borders.
  const octomap::point3d pf(static_cast<float>(p.x()), static_cast<float>(p.y()),
                            static_cast<float>(p.z()));
  if (options_.max_range_m > 0.0) {
    const octomap::point3d d = pf - origin_;
    if (static_cast<double>(d.norm()) > options_.max_range_m) {
      // OctoMap's maxrange rule: free up to max_range_m, no hit.
      AddFreeEnd(origin_ + d.normalized() * static_cast<float>(options_.max_range_m));
      return;
    }
  }
  octomap::OcTreeKey key;
  unsigned cell = 0;
  if (!KeyOf(pf, resolution_factor_, options_.ray_cells_per_voxel_edge, &key, &cell)) {
    ++stats_.skipped_points;
    return;
  }
  ++stats_.hit_points;
  AddRayTarget(key, cell, kHit | kRayEnd, pf);
}

void FastOctreeInserter::AddFreeEnd(const octomap::point3d& end) {
  octomap::OcTreeKey key;
  unsigned cell = 0;
  if (!KeyOf(end, resolution_factor_, options_.ray_cells_per_voxel_edge, &key, &cell)) {
    ++stats_.skipped_points;
    return;
  }
  ++stats_.free_points;
  AddRayTarget(key, cell, kRayEnd, end);
}

void FastOctreeInserter::AddRayTarget(const octomap::OcTreeKey& key, unsigned cell, uint8_t flags,
                                      const octomap::point3d& p) {
  const uint64_t packed = Pack(key);
  const uint64_t tagged = packed | (uint64_t{flags} << 48) | (uint64_t{cell} << 56);
  if (tagged != last_tagged_key_) {  // else: the neighbouring pixel's cell again
    const KeyFlagTable::Slot slot = table_.OrAt(packed, flags);
    std::size_t base = 0;
    if ((slot.before & kRayEnd) == 0) {
      // A new endpoint voxel: a block of ray cells, empty until used.
      base = targets_.size();
      table_.value(slot.index) = static_cast<uint32_t>(base);
      targets_.resize(base + cells_per_voxel_);
      for (std::size_t i = base; i < targets_.size(); ++i) targets_[i] = {.key = packed};
    } else {
      base = table_.value(slot.index);
    }
    last_tagged_key_ = tagged;
    last_target_ = base + cell;
  }
  RayTarget& t = targets_[last_target_];
  t.sum += Eigen::Vector3d(p.x(), p.y(), p.z());
  ++t.count;
}

void FastOctreeInserter::CastRays(const octomap::OcTree& tree) {
  for (const RayTarget& target : targets_) {
    if (target.count == 0) continue;
    // To the centroid of the cell's endpoints: the one ray stands for all
    // of them, and where they lie on a surface, so does it (a ray to the
    // voxel's centre would end up to half a voxel behind or before the
    // surface and clear voxels the pixels' rays never reach). Both ends
    // are in the key range, so computeRayKeys cannot fail.
    const Eigen::Vector3d c = target.sum / static_cast<double>(target.count);
    octomap::point3d end(static_cast<float>(c.x()), static_cast<float>(c.y()),
                         static_cast<float>(c.z()));
    octomap::OcTreeKey end_key;
    unsigned cell = 0;
    if (!KeyOf(end, resolution_factor_, 1, &end_key, &cell) || Pack(end_key) != target.key) {
      end = tree.keyToCoord(Unpack(target.key));  // rounded onto a border
      end_key = Unpack(target.key);
    }
    // A DDA ray steps at most the L1 key distance; OctoMap's KeyRay holds
    // a fixed number of keys and does not check in release builds.
    std::size_t steps = 0;
    for (unsigned i = 0; i < 3; ++i) {
      steps += static_cast<std::size_t>(std::abs(int{end_key[i]} - int{origin_key_[i]}));
    }
    if (steps + 2 >= ray_.sizeMax()) {
      ++stats_.skipped_rays;
      continue;
    }
    tree.computeRayKeys(origin_, end, ray_);
    ++stats_.rays_cast;
    stats_.ray_keys += ray_.size();
    for (const octomap::OcTreeKey& k : ray_) table_.Or(Pack(k), kTraversed);
  }
}

void FastOctreeInserter::UpdateTree(octomap::OcTree* tree) {
  updates_.clear();
  table_.ForEach([this](uint64_t packed, uint8_t flags) {
    if ((flags & kHit) != 0) {
      updates_.push_back((MortonOfPacked(packed) << 1) | 1);
      ++stats_.occupied_keys;
    } else if ((flags & kTraversed) != 0) {
      updates_.push_back(MortonOfPacked(packed) << 1);
      ++stats_.free_keys;
    }
  });
  if (updates_.empty()) return;
  RadixSort(updates_, scratch_, radix_counts_);

  octomap::OcTree& t = *tree;
  if (t.isChangeDetectionEnabled()) {
    // The path walk below bypasses OctoMap's change tracking.
    for (const uint64_t u : updates_) t.updateNode(KeyOfMorton(u >> 1), (u & 1) != 0, true);
    t.updateInnerOccupancy();
    return;
  }
  if (t.getRoot() == nullptr) {
    // Only OctoMap may create the root: let it, with a zero update on the
    // first key's path (the key's real update follows).
    t.updateNode(KeyOfMorton(updates_.front() >> 1), 0.0f, true);
  }
  const float hit_log = t.getProbHitLog();
  const float miss_log = t.getProbMissLog();
  // path[d]: the node at depth d on the way to the previous key.
  std::array<octomap::OcTreeNode*, kTreeDepth + 1> path{};
  path[0] = t.getRoot();
  uint64_t previous = 0;
  bool first = true;
  for (const uint64_t u : updates_) {
    const uint64_t morton = u >> 1;
    int depth = 0;
    if (!first) {
      // Levels shared with the previous key: 3 Morton bits per level in a
      // 48-bit code. Below them the previous path is finished (keys are
      // sorted): give its inner nodes their children's maximum, as
      // updateInnerOccupancy would.
      depth = (std::countl_zero(morton ^ previous) - 16) / 3;
      for (int d = kTreeDepth - 1; d > depth; --d)
        path[static_cast<std::size_t>(d)]->updateOccupancyChildren();
    }
    const octomap::OcTreeKey key = KeyOfMorton(morton);
    bool just_created = false;
    for (int d = depth; d < kTreeDepth; ++d) {
      octomap::OcTreeNode* node = path[static_cast<std::size_t>(d)];
      const unsigned pos = octomap::computeChildIdx(key, kTreeDepth - 1 - d);
      const bool exists = t.nodeChildExists(node, pos);
      if (!exists && !t.nodeHasChildren(node) && !just_created) {
        // A pruned node: as OctoMap's updateNode, expand it into 8 copies.
        t.expandNode(node);
        just_created = false;
      } else if (!exists) {
        t.createNodeChild(node, pos);
        just_created = true;
      } else {
        just_created = false;
      }
      path[static_cast<std::size_t>(d + 1)] = t.getNodeChild(node, pos);
    }
    // Clamped like updateNode (which would skip the update at the bound).
    t.updateNodeLogOdds(path[kTreeDepth], (u & 1) != 0 ? hit_log : miss_log);
    previous = morton;
    first = false;
  }
  for (int d = kTreeDepth - 1; d >= 0; --d)
    path[static_cast<std::size_t>(d)]->updateOccupancyChildren();
}

}  // namespace rover::mapping
