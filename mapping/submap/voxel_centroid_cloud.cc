#include "mapping/submap/voxel_centroid_cloud.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

namespace rover::mapping {
namespace {

constexpr int64_t kOffset = int64_t{1} << 20;  // voxel indices in [-2^20, 2^20)
constexpr std::size_t kInitialSlots = 1 << 12;

std::size_t Hash(uint64_t key) {
  return static_cast<std::size_t>((key * 0x9E3779B97F4A7C15ull) >> 32);
}

}  // namespace

VoxelCentroidCloud::VoxelCentroidCloud(double resolution_m) : resolution_m_(resolution_m) {
  if (!(std::isfinite(resolution_m) && resolution_m > 0.0)) {
    throw std::invalid_argument("VoxelCentroidCloud: expected resolution_m > 0, got " +
                                std::to_string(resolution_m));
  }
  slot_keys_.assign(kInitialSlots, 0);
  slot_index_.assign(kInitialSlots, 0);
  mask_ = kInitialSlots - 1;
}

bool VoxelCentroidCloud::Add(const Eigen::Vector3f& p_submap_m, bool obstacle) {
  if (!p_submap_m.allFinite()) return false;
  uint64_t key = 0;
  for (int axis = 0; axis < 3; ++axis) {
    const double i = std::floor(static_cast<double>(p_submap_m[axis]) / resolution_m_);
    if (!(i >= -static_cast<double>(kOffset) && i < static_cast<double>(kOffset))) return false;
    key |= static_cast<uint64_t>(static_cast<int64_t>(i) + kOffset) << (21 * axis);
  }
  std::size_t index = 0;
  if (has_last_ && key == last_key_) {
    index = last_index_;
  } else {
    index = Find(key);
    last_key_ = key;
    last_index_ = index;
    has_last_ = true;
  }
  Voxel& voxel = voxels_[index];
  voxel.sum += p_submap_m.cast<double>();
  ++voxel.count;
  voxel.obstacle = voxel.obstacle || obstacle;
  return true;
}

std::size_t VoxelCentroidCloud::Find(uint64_t key) {
  for (std::size_t s = Hash(key) & mask_;; s = (s + 1) & mask_) {
    if (slot_keys_[s] == key + 1) return slot_index_[s];
    if (slot_keys_[s] == 0) {
      if (2 * (voxels_.size() + 1) > slot_keys_.size()) {
        Grow();
        return Find(key);
      }
      slot_keys_[s] = key + 1;
      slot_index_[s] = static_cast<uint32_t>(voxels_.size());
      voxels_.push_back({.key = key});
      return voxels_.size() - 1;
    }
  }
}

void VoxelCentroidCloud::Grow() {
  const std::size_t slots = slot_keys_.size() * 2;
  slot_keys_.assign(slots, 0);
  slot_index_.assign(slots, 0);
  mask_ = slots - 1;
  for (std::size_t i = 0; i < voxels_.size(); ++i) {
    std::size_t s = Hash(voxels_[i].key) & mask_;
    while (slot_keys_[s] != 0) s = (s + 1) & mask_;
    slot_keys_[s] = voxels_[i].key + 1;
    slot_index_[s] = static_cast<uint32_t>(i);
  }
}

PointCloud VoxelCentroidCloud::Points() const {
  std::vector<std::pair<uint64_t, uint32_t>> order;
  order.reserve(voxels_.size());
  for (std::size_t i = 0; i < voxels_.size(); ++i) {
    order.emplace_back(voxels_[i].key, static_cast<uint32_t>(i));
  }
  // The key holds z in its top bits, then y, then x: sorting it sorts the
  // voxel indices lexicographically.
  std::sort(order.begin(), order.end());
  PointCloud cloud;
  cloud.reserve(order.size());
  for (const auto& [key, i] : order) {
    const Voxel& v = voxels_[i];
    cloud.push_back({.p_submap_m = (v.sum / static_cast<double>(v.count)).cast<float>(),
                     .obstacle = v.obstacle});
  }
  return cloud;
}

void VoxelCentroidCloud::Clear() {
  voxels_.clear();
  std::fill(slot_keys_.begin(), slot_keys_.end(), uint64_t{0});
  has_last_ = false;
}

}  // namespace rover::mapping
