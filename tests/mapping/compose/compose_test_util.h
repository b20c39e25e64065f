#ifndef ROVER_TESTS_MAPPING_COMPOSE_COMPOSE_TEST_UTIL_H_
#define ROVER_TESTS_MAPPING_COMPOSE_COMPOSE_TEST_UTIL_H_

// Helpers shared by the mapping/compose tests: submap-like octrees and a view
// of a tree as finest voxels, independent of how it happens to be pruned.

#include <cmath>
#include <map>
#include <memory>
#include <random>
#include <tuple>

#include <octomap/OcTree.h>
#include <Eigen/Geometry>

namespace rover::mapping::testing {

inline constexpr double kResolutionM = 0.1;

/// Log-odds of a probability, as octomap computes it.
inline float LogOdds(double p) { return octomap::logodds(p); }

/// A submap octree with the submap parameters (10 cm, hit 0.7, miss 0.4,
/// clamping 0.12 / 0.97).
inline std::shared_ptr<octomap::OcTree> MakeSubmapTree() {
  auto tree = std::make_shared<octomap::OcTree>(kResolutionM);
  tree->setProbHit(0.7);
  tree->setProbMiss(0.4);
  tree->setClampingThresMin(0.12);
  tree->setClampingThresMax(0.97);
  return tree;
}

/// Sets the finest voxel holding `p` (submap frame) to `log_odds`.
inline void SetVoxel(octomap::OcTree* tree, const Eigen::Vector3d& p, float log_odds) {
  tree->setNodeValue(octomap::point3d(static_cast<float>(p.x()), static_cast<float>(p.y()),
                                      static_cast<float>(p.z())),
                     log_odds, /*lazy_eval=*/false);
}

using KeyTuple = std::tuple<int, int, int>;

inline KeyTuple KeyOf(const octomap::OcTree& tree, const Eigen::Vector3d& p) {
  const octomap::OcTreeKey k = tree.coordToKey(p.x(), p.y(), p.z());
  return {k[0], k[1], k[2]};
}

/// Every known finest voxel of `tree` and its log-odds. Pruned leaves are
/// expanded from their centre and size as octomap reports them.
inline std::map<KeyTuple, float> FinestVoxels(const octomap::OcTree& tree) {
  std::map<KeyTuple, float> voxels;
  const double res = tree.getResolution();
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) {
    const double size = it.getSize();
    const int n = static_cast<int>(std::lround(size / res));
    const octomap::point3d centre = it.getCoordinate();
    const Eigen::Vector3d c = Eigen::Vector3f(centre.x(), centre.y(), centre.z()).cast<double>();
    for (int i = 0; i < n; ++i) {
      for (int j = 0; j < n; ++j) {
        for (int l = 0; l < n; ++l) {
          const Eigen::Vector3d p(c.x() - size / 2 + res * (i + 0.5),
                                  c.y() - size / 2 + res * (j + 0.5),
                                  c.z() - size / 2 + res * (l + 0.5));
          voxels[KeyOf(tree, p)] = it->getLogOdds();
        }
      }
    }
  }
  return voxels;
}

/// A random submap-like tree: a bumpy ground patch of `size_m` around
/// `centre`, occupied, with free space above it, plus some free voxels
/// measured several times (so that free space prunes).
inline std::shared_ptr<octomap::OcTree> RandomSubmapTree(std::mt19937* rng,
                                                         const Eigen::Vector3d& centre,
                                                         double size_m) {
  auto tree = MakeSubmapTree();
  std::uniform_real_distribution<double> bump(-0.1, 0.1);
  std::uniform_int_distribution<int> hits(1, 3);
  for (double x = -size_m / 2; x < size_m / 2; x += kResolutionM) {
    for (double y = -size_m / 2; y < size_m / 2; y += kResolutionM) {
      const double ground = bump(*rng);
      const Eigen::Vector3d p = centre + Eigen::Vector3d(x, y, ground);
      for (int h = hits(*rng); h > 0; --h) {
        tree->updateNode(octomap::point3d(static_cast<float>(p.x()), static_cast<float>(p.y()),
                                          static_cast<float>(p.z())),
                         true, true);
      }
      for (double z = 0.15; z < 0.8; z += kResolutionM) {
        const Eigen::Vector3d q = p + Eigen::Vector3d(0, 0, z);
        for (int h = 0; h < 8; ++h) {
          tree->updateNode(octomap::point3d(static_cast<float>(q.x()), static_cast<float>(q.y()),
                                            static_cast<float>(q.z())),
                           false, true);
        }
      }
    }
  }
  tree->updateInnerOccupancy();
  tree->prune();
  return tree;
}

inline Eigen::Isometry3d Pose(double x, double y, double z, double yaw_rad) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(x, y, z);
  return T;
}

}  // namespace rover::mapping::testing

#endif  // ROVER_TESTS_MAPPING_COMPOSE_COMPOSE_TEST_UTIL_H_
