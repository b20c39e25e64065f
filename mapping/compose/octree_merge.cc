#include "mapping/compose/octree_merge.h"

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>

namespace rover::mapping {
namespace {

// octomap's key of a coordinate: floor(coordinate / resolution) + 2^15, kept
// signed here so that out-of-range keys can be detected before narrowing.
constexpr int64_t kKeyOffset = 32768;
constexpr int64_t kKeyMax = 65535;

// Slack (in voxels) when selecting the global centres a leaf's cube may
// contain: a centre on the cube's face must be examined by both leaves that
// share the face, and the containment test (exact floor tiling) gives it to
// one of them. Without the slack rounding could skip it in both: a hole.
constexpr double kRangeSlackVoxels = 1e-6;

class Merger {
 public:
  Merger(const octomap::OcTree& source, const Eigen::Isometry3d& T_target_source, bool lazy_eval,
         octomap::OcTree* target, std::vector<VoxelUndo>* undo)
      : source_(source),
        T_target_source_(T_target_source),
        T_source_target_(T_target_source.inverse()),
        lazy_eval_(lazy_eval),
        target_(target),
        undo_(undo),
        resolution_m_(target->getResolution()),
        inv_resolution_(1.0 / target->getResolution()) {}

  OctreeMergeStats Run() {
    const unsigned tree_depth = source_.getTreeDepth();
    for (auto it = source_.begin_leafs(), end = source_.end_leafs(); it != end; ++it) {
      const unsigned span = 1u << (tree_depth - it.getDepth());
      if (span > kMaxLeafSpanVoxels) {
        throw std::invalid_argument("MergeOctree: source leaf spans " + std::to_string(span) +
                                    " voxels per edge, more than " +
                                    std::to_string(kMaxLeafSpanVoxels));
      }
      MergeLeaf(it.getKey(), span, it->getLogOdds(), source_.isNodeOccupied(*it));
    }
    return stats_;
  }

 private:
  // Samples one source leaf: key range [lo, lo + span) per axis in the source.
  void MergeLeaf(const octomap::OcTreeKey& key, unsigned span, float log_odds, bool occupied) {
    std::array<int64_t, 3> lo{};
    for (unsigned a = 0; a < 3; ++a) {
      // Every key inside a node shares the node's leading bits, whatever
      // key the iterator reports for it.
      lo[a] = static_cast<int64_t>(static_cast<unsigned>(key[a]) & ~(span - 1u));
    }
    // The leaf's cube in the target frame, bounded by its 8 corners.
    Eigen::Vector3d min_m = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
    Eigen::Vector3d max_m = -min_m;
    for (int corner = 0; corner < 8; ++corner) {
      Eigen::Vector3d p_source;
      for (int a = 0; a < 3; ++a) {
        const int64_t k = lo[static_cast<std::size_t>(a)] + (((corner >> a) & 1) ? span : 0);
        p_source[a] = static_cast<double>(k - kKeyOffset) * resolution_m_;
      }
      const Eigen::Vector3d p_target = T_target_source_ * p_source;
      min_m = min_m.cwiseMin(p_target);
      max_m = max_m.cwiseMax(p_target);
    }
    // Keys whose centres (k - 2^15 + 0.5) * resolution lie in the box.
    std::array<int64_t, 3> first{};
    std::array<int64_t, 3> last{};
    for (int a = 0; a < 3; ++a) {
      const auto ua = static_cast<std::size_t>(a);
      first[ua] =
          static_cast<int64_t>(std::ceil(min_m[a] * inv_resolution_ - 0.5 - kRangeSlackVoxels)) +
          kKeyOffset;
      last[ua] =
          static_cast<int64_t>(std::floor(max_m[a] * inv_resolution_ - 0.5 + kRangeSlackVoxels)) +
          kKeyOffset;
      if (first[ua] < 0 || last[ua] > kKeyMax) {
        ++stats_.out_of_range_leaves;
        return;
      }
    }
    std::size_t sampled = 0;
    for (int64_t x = first[0]; x <= last[0]; ++x) {
      for (int64_t y = first[1]; y <= last[1]; ++y) {
        for (int64_t z = first[2]; z <= last[2]; ++z) {
          const Eigen::Vector3d centre_target = Centre(x, y, z);
          if (!Contains(T_source_target_ * centre_target, lo, span)) continue;
          Update(octomap::OcTreeKey(Narrow(x), Narrow(y), Narrow(z)), log_odds);
          ++sampled;
        }
      }
    }
    if (sampled > 0 || !occupied) return;
    // An occupied voxel between the target centres: push it to the voxel
    // holding its centre rather than lose an obstacle.
    const double half_span = 0.5 * static_cast<double>(span);
    Eigen::Vector3d centre_source;
    for (int a = 0; a < 3; ++a) {
      centre_source[a] =
          (static_cast<double>(lo[static_cast<std::size_t>(a)] - kKeyOffset) + half_span) *
          resolution_m_;
    }
    const Eigen::Vector3d centre_target = T_target_source_ * centre_source;
    std::array<int64_t, 3> k{};
    for (int a = 0; a < 3; ++a) {
      k[static_cast<std::size_t>(a)] =
          static_cast<int64_t>(std::floor(centre_target[a] * inv_resolution_)) + kKeyOffset;
      if (k[static_cast<std::size_t>(a)] < 0 || k[static_cast<std::size_t>(a)] > kKeyMax) {
        ++stats_.out_of_range_leaves;
        return;
      }
    }
    Update(octomap::OcTreeKey(Narrow(k[0]), Narrow(k[1]), Narrow(k[2])), log_odds);
    ++stats_.pushed_leaves;
  }

  Eigen::Vector3d Centre(int64_t x, int64_t y, int64_t z) const {
    return {(static_cast<double>(x - kKeyOffset) + 0.5) * resolution_m_,
            (static_cast<double>(y - kKeyOffset) + 0.5) * resolution_m_,
            (static_cast<double>(z - kKeyOffset) + 0.5) * resolution_m_};
  }

  // Whether a source-frame point lies in the leaf's key range; the floor
  // tiles space exactly, so a point belongs to one leaf only.
  bool Contains(const Eigen::Vector3d& p_source, const std::array<int64_t, 3>& lo,
                unsigned span) const {
    for (int a = 0; a < 3; ++a) {
      const double k = std::floor(p_source[a] * inv_resolution_);
      const double offset = k + static_cast<double>(kKeyOffset - lo[static_cast<std::size_t>(a)]);
      if (!(offset >= 0.0 && offset < static_cast<double>(span))) return false;
    }
    return true;
  }

  static octomap::key_type Narrow(int64_t k) { return static_cast<octomap::key_type>(k); }

  void Update(const octomap::OcTreeKey& key, float log_odds) {
    if (undo_ != nullptr) {
      const octomap::OcTreeNode* node = target_->search(key);
      undo_->push_back(VoxelUndo{key, node != nullptr, node ? node->getLogOdds() : 0.0f});
    }
    // Adds and clamps (OccupancyOcTreeBase::updateNodeLogOdds).
    target_->updateNode(key, log_odds, lazy_eval_);
    ++stats_.voxels_updated;
  }

  const octomap::OcTree& source_;
  const Eigen::Isometry3d T_target_source_;
  const Eigen::Isometry3d T_source_target_;
  const bool lazy_eval_;
  octomap::OcTree* target_;
  std::vector<VoxelUndo>* undo_;
  const double resolution_m_;
  const double inv_resolution_;
  OctreeMergeStats stats_;
};

}  // namespace

void CheckLeafSpans(const octomap::OcTree& tree, const char* what) {
  const unsigned tree_depth = tree.getTreeDepth();
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) {
    const unsigned span = 1u << (tree_depth - it.getDepth());
    if (span > kMaxLeafSpanVoxels) {
      throw std::invalid_argument(std::string(what) + ": a leaf spans " + std::to_string(span) +
                                  " voxels per edge, more than " +
                                  std::to_string(kMaxLeafSpanVoxels) + " (corrupt octree?)");
    }
  }
}

OctreeMergeStats MergeOctree(const octomap::OcTree& source,
                             const Eigen::Isometry3d& T_target_source, bool lazy_eval,
                             octomap::OcTree* target, std::vector<VoxelUndo>* undo) {
  const double resolution_m = target->getResolution();
  if (std::abs(source.getResolution() - resolution_m) > 1e-9 * resolution_m) {
    // Sampling a grid of another pitch would need interpolation.
    throw std::invalid_argument(
        "MergeOctree: source resolution " + std::to_string(source.getResolution()) +
        " m differs from target resolution " + std::to_string(resolution_m) + " m");
  }
  if (!T_target_source.matrix().allFinite()) {
    throw std::invalid_argument("MergeOctree: T_target_source is not finite");
  }
  return Merger(source, T_target_source, lazy_eval, target, undo).Run();
}

void UndoMerge(std::vector<VoxelUndo>* undo, octomap::OcTree* target) {
  for (auto it = undo->rbegin(); it != undo->rend(); ++it) {
    if (it->existed) {
      target->setNodeValue(it->key, it->log_odds, /*lazy_eval=*/false);
    } else {
      DeleteVoxel(it->key, target);
    }
  }
  undo->clear();
}

bool DeleteVoxel(const octomap::OcTreeKey& key, octomap::OcTree* tree) {
  octomap::OcTreeNode* node = tree->getRoot();
  if (node == nullptr) return false;
  const unsigned tree_depth = tree->getTreeDepth();
  std::vector<octomap::OcTreeNode*> path(tree_depth);
  std::vector<unsigned> child_index(tree_depth);
  for (unsigned d = 0; d < tree_depth; ++d) {
    path[d] = node;
    child_index[d] = octomap::computeChildIdx(key, static_cast<int>(tree_depth - 1 - d));
    if (!tree->nodeChildExists(node, child_index[d])) {
      if (tree->nodeHasChildren(node)) return false;  // unknown
      tree->expandNode(node);                         // a pruned leaf holds the voxel
    }
    node = tree->getNodeChild(node, child_index[d]);
  }
  for (unsigned d = tree_depth; d-- > 0;) {
    octomap::OcTreeNode* parent = path[d];
    tree->deleteNodeChild(parent, child_index[d]);
    if (tree->nodeHasChildren(parent)) {
      // Inner nodes hold the maximum of their children.
      for (unsigned up = d + 1; up-- > 0;) path[up]->updateOccupancyChildren();
      return true;
    }
    if (d == 0) {
      tree->clear();  // the root lost its last child: the tree is empty
      return true;
    }
    // `parent` has no children left but still owns its child array, which
    // deleteNodeChild would not free. Refilling and collapsing it is the
    // public way to release that array and make `parent` a plain leaf.
    tree->expandNode(parent);
    tree->pruneNode(parent);
  }
  return true;
}

}  // namespace rover::mapping
