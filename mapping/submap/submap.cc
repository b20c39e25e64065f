#include "mapping/submap/submap.h"

#include <stdexcept>
#include <string>

namespace rover::mapping {
namespace {

std::unique_ptr<octomap::OcTree> MakeTree(const SubmapOptions& options) {
  options.Validate();
  auto tree = std::make_unique<octomap::OcTree>(options.octree_resolution_m);
  tree->setProbHit(options.prob_hit);
  tree->setProbMiss(options.prob_miss);
  tree->setClampingThresMin(options.clamping_min);
  tree->setClampingThresMax(options.clamping_max);
  return tree;
}

}  // namespace

Submap::Submap(uint32_t index, uint32_t frame_id, const SubmapOptions& options)
    : index_(index),
      frame_id_(frame_id),
      options_(options),
      tree_(MakeTree(options)),
      inserter_(options),
      cloud_(options.cloud_resolution_m) {}

void Submap::Integrate(const DepthImage& depth, const std::vector<uint8_t>& obstacle_mask,
                       const Eigen::Isometry3d& T_submap_cam) {
  if (finished_) {
    throw std::logic_error("Submap " + std::to_string(index_) +
                           ": Integrate after Finish (a finished submap is frozen)");
  }
  const std::size_t pixels =
      static_cast<std::size_t>(depth.width()) * static_cast<std::size_t>(depth.height());
  if (!obstacle_mask.empty() && obstacle_mask.size() != pixels) {
    throw std::invalid_argument("Submap::Integrate: expected an obstacle mask of " +
                                std::to_string(pixels) + " bytes (or none), got " +
                                std::to_string(obstacle_mask.size()));
  }
  inserter_.Insert(depth, T_submap_cam, tree_.get());

  // Points beyond max_range_m carry large stereo errors: the thesis drops
  // them from the cloud as well.
  const double max_range_sq = options_.max_range_m * options_.max_range_m;
  for (int v = 0; v < depth.height(); ++v) {
    for (int u = 0; u < depth.width(); ++u) {
      if (depth.state(u, v) != DepthState::kValid) continue;
      const Eigen::Vector3f& p_cam = depth.point(u, v);
      if (max_range_sq > 0.0 && p_cam.cast<double>().squaredNorm() > max_range_sq) continue;
      const std::size_t i = static_cast<std::size_t>(v) * static_cast<std::size_t>(depth.width()) +
                            static_cast<std::size_t>(u);
      const bool obstacle = !obstacle_mask.empty() && obstacle_mask[i] != 0;
      cloud_.Add((T_submap_cam * p_cam.cast<double>()).cast<float>(), obstacle);
    }
  }
  ++images_;
}

void Submap::Finish() {
  tree_->prune();
  finished_ = true;
}

}  // namespace rover::mapping
