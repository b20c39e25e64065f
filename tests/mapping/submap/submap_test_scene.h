#ifndef ROVER_TESTS_MAPPING_SUBMAP_SUBMAP_TEST_SCENE_H_
#define ROVER_TESTS_MAPPING_SUBMAP_SUBMAP_TEST_SCENE_H_

// Synthetic depth images and the stock-OctoMap reference for the submap
// tests and bench/mapping: a ground plane with spherical rocks seen by the
// simulator's 752x480 stereo head, its disparity computed analytically per
// pixel (ray against plane and spheres, exact up to SGBM's 1/16 px), and
// ground beyond a "stereo range" rendered with zero disparity, as SGBM
// leaves what is too far to match. Also: octomap::OcTree::insertPointCloud
// on the same points, and the voxel sets used to compare the two trees.

#include <cmath>
#include <cstdint>
#include <limits>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include <octomap/OcTree.h>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "mapping/depth/depth_image.h"
#include "tests/mapping/mapping_test_head.h"

namespace rover::mapping::testing {

struct Rock {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  double radius_m = 0.0;
};

struct Scene {
  /// Ground plane z = ground_z_m + slope_x * x + slope_y * y.
  double ground_z_m = 0.0;
  double slope_x = 0.0;
  double slope_y = 0.0;
  std::vector<Rock> rocks;
  /// Surfaces farther from the camera get zero disparity ("infinite").
  double stereo_range_m = 8.0;
  /// Every n-th pixel (0: none) gets no match, as SGBM leaves some.
  int invalid_every = 0;
};

/// Gently sloped ground about 0.7 m below a camera at the origin, with
/// rocks ahead. The slope keeps the ground from lying along voxel borders
/// everywhere, which no real terrain does.
inline Scene RockyGround() {
  Scene scene;
  scene.ground_z_m = -0.02;
  scene.slope_x = 0.03;
  scene.slope_y = -0.02;
  scene.rocks = {{{2.0, 0.2, 0.05}, 0.25},
                 {{3.0, -0.8, 0.0}, 0.35},
                 {{4.5, 1.2, -0.1}, 0.5},
                 {{1.4, -0.4, -0.05}, 0.12}};
  scene.stereo_range_m = 4.5;
  return scene;
}

/// Range along the camera ray through pixel (u, v) to the first surface, or
/// infinity.
inline double RayRange(const Eigen::Vector3d& c, const Eigen::Vector3d& d, const Scene& scene) {
  double best = std::numeric_limits<double>::infinity();
  // n . (c + t d) = ground_z_m with n = (-slope_x, -slope_y, 1).
  const Eigen::Vector3d n(-scene.slope_x, -scene.slope_y, 1.0);
  const double nd = n.dot(d);
  if (nd < 0.0) {
    const double t = (scene.ground_z_m - n.dot(c)) / nd;
    if (t > 0.0) best = t;
  }
  for (const Rock& rock : scene.rocks) {
    const Eigen::Vector3d oc = c - rock.centre;
    const double b = oc.dot(d);
    const double disc = b * b - (oc.squaredNorm() - rock.radius_m * rock.radius_m);
    if (disc < 0.0) continue;
    const double t = -b - std::sqrt(disc);
    if (t > 0.0 && t < best) best = t;
  }
  return best;
}

/// The disparity image (CV_16S, 16 per px) of `scene` seen from
/// T_world_cam.
inline cv::Mat RenderDisparity(const RectifiedStereo& s, const Eigen::Isometry3d& T_world_cam,
                               const Scene& scene) {
  cv::Mat disparity(s.height_px, s.width_px, CV_16SC1, cv::Scalar(0));
  const Eigen::Vector3d c = T_world_cam.translation();
  int pixel = 0;
  for (int v = 0; v < s.height_px; ++v) {
    for (int u = 0; u < s.width_px; ++u, ++pixel) {
      if (scene.invalid_every > 0 && pixel % scene.invalid_every == 0) {
        disparity.at<int16_t>(v, u) = -16;
        continue;
      }
      const Eigen::Vector3d ray_cam((u - s.cx_px) / s.focal_px, (v - s.cy_px) / s.focal_px, 1.0);
      const Eigen::Vector3d d = T_world_cam.linear() * ray_cam.normalized();
      const double range = RayRange(c, d, scene);
      if (!(range < scene.stereo_range_m)) continue;  // zero disparity
      const double z_cam = range / ray_cam.norm();
      const double disparity_px = s.focal_px * s.baseline_m / z_cam;
      disparity.at<int16_t>(v, u) = static_cast<int16_t>(std::lround(16.0 * disparity_px));
    }
  }
  return disparity;
}

/// The depth image of `scene`; `max_depth_sigma_m` large keeps every
/// rendered point valid.
inline DepthImage RenderDepth(const RectifiedStereo& s, const Eigen::Isometry3d& T_world_cam,
                              const Scene& scene, double max_depth_sigma_m = 0.15) {
  const StereoErrorModel model(s, 0.5);
  return DepthImage::FromDisparity(RenderDisparity(s, T_world_cam, scene), model,
                                   {.max_depth_sigma_m = max_depth_sigma_m});
}

/// A depth image's beams in the world frame, computed exactly as
/// FastOctreeInserter::Insert does.
struct Scan {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> hits;       ///< kValid points
  std::vector<Eigen::Vector3d> free_ends;  ///< kInfinite rays, max_free_range_m long
};

inline Scan ScanOf(const DepthImage& depth, const Eigen::Isometry3d& T_world_cam,
                   double max_free_range_m) {
  Scan scan;
  scan.origin = T_world_cam.translation();
  for (int v = 0; v < depth.height(); ++v) {
    for (int u = 0; u < depth.width(); ++u) {
      if (depth.state(u, v) == DepthState::kValid) {
        scan.hits.push_back(T_world_cam * depth.point(u, v).cast<double>());
      } else if (depth.state(u, v) == DepthState::kInfinite && max_free_range_m > 0.0) {
        scan.free_ends.push_back(
            scan.origin + max_free_range_m * (T_world_cam.linear() * depth.Ray(u, v).normalized()));
      }
    }
  }
  return scan;
}

/// The scan with every endpoint moved to the centre of its voxel of `tree`
/// (as insertPointCloud's discretize = true does).
inline Scan SnapToVoxelCentres(const Scan& scan, const octomap::OcTree& tree) {
  const auto snap = [&tree](const Eigen::Vector3d& p) {
    const octomap::point3d c = tree.keyToCoord(tree.coordToKey(octomap::point3d(
        static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z()))));
    return Eigen::Vector3d(c.x(), c.y(), c.z());
  };
  Scan out;
  out.origin = scan.origin;
  for (const Eigen::Vector3d& p : scan.hits) out.hits.push_back(snap(p));
  for (const Eigen::Vector3d& p : scan.free_ends) out.free_ends.push_back(snap(p));
  return out;
}

/// Ground height under (x, y).
inline double GroundHeight(const Scene& scene, double x_m, double y_m) {
  return scene.ground_z_m + scene.slope_x * x_m + scene.slope_y * y_m;
}

inline octomap::point3d ToPoint3d(const Eigen::Vector3d& p) {
  return {static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z())};
}

inline octomap::Pointcloud ToPointcloud(const std::vector<Eigen::Vector3d>& points) {
  octomap::Pointcloud cloud;
  cloud.reserve(points.size());
  for (const Eigen::Vector3d& p : points) cloud.push_back(ToPoint3d(p));
  return cloud;
}

/// Stock OctoMap on a scan. Without free ends this is exactly
/// tree->insertPointCloud(hits, origin, max_range_m, lazy_eval = false,
/// discretize). With them, the same scan update (computeUpdate or
/// computeDiscreteUpdate) plus computeRayKeys for each free end (to its
/// voxel centre when discretising) in the same key sets, occupied winning,
/// then one non-lazy updateNode per key, as insertPointCloud does.
/// `max_range_m` < 0: unlimited.
inline void ReferenceInsert(const Scan& scan, double max_range_m, bool discretize,
                            octomap::OcTree* tree) {
  const octomap::Pointcloud cloud = ToPointcloud(scan.hits);
  const octomap::point3d origin = ToPoint3d(scan.origin);
  if (scan.free_ends.empty()) {
    tree->insertPointCloud(cloud, origin, max_range_m, false, discretize);
    return;
  }
  octomap::KeySet free_cells, occupied_cells;
  if (discretize) {
    tree->computeDiscreteUpdate(cloud, origin, free_cells, occupied_cells, max_range_m);
  } else {
    tree->computeUpdate(cloud, origin, free_cells, occupied_cells, max_range_m);
  }
  octomap::KeyRay ray;
  for (const Eigen::Vector3d& e : scan.free_ends) {
    octomap::point3d end = ToPoint3d(e);
    if (discretize) end = tree->keyToCoord(tree->coordToKey(end));
    if (tree->computeRayKeys(origin, end, ray)) free_cells.insert(ray.begin(), ray.end());
  }
  for (const octomap::OcTreeKey& k : occupied_cells) free_cells.erase(k);
  for (const octomap::OcTreeKey& k : free_cells) tree->updateNode(k, false, false);
  for (const octomap::OcTreeKey& k : occupied_cells) tree->updateNode(k, true, false);
}

inline uint64_t PackKey(const octomap::OcTreeKey& k) {
  return uint64_t{k[0]} | (uint64_t{k[1]} << 16) | (uint64_t{k[2]} << 32);
}

/// A tree's known voxels at full resolution (pruned nodes expanded).
struct VoxelSets {
  std::unordered_set<uint64_t> occupied;
  std::unordered_set<uint64_t> free;
  std::unordered_map<uint64_t, float> log_odds;
};

inline VoxelSets LeafVoxels(const octomap::OcTree& tree) {
  octomap::OcTree expanded(tree);
  expanded.expand();
  VoxelSets sets;
  for (auto it = expanded.begin_leafs(), end = expanded.end_leafs(); it != end; ++it) {
    const uint64_t key = PackKey(it.getKey());
    (expanded.isNodeOccupied(*it) ? sets.occupied : sets.free).insert(key);
    sets.log_odds[key] = it->getLogOdds();
  }
  return sets;
}

/// |A n B| / |A u B| (1 for two empty sets).
inline double Jaccard(const std::unordered_set<uint64_t>& a,
                      const std::unordered_set<uint64_t>& b) {
  std::size_t common = 0;
  for (const uint64_t k : a) common += b.count(k);
  const std::size_t all = a.size() + b.size() - common;
  return all == 0 ? 1.0 : static_cast<double>(common) / static_cast<double>(all);
}

/// How far two trees' occupancy agree.
struct Agreement {
  double occupied_jaccard = 0.0;
  double free_jaccard = 0.0;
  std::size_t occupied_a = 0, occupied_b = 0, free_a = 0, free_b = 0;
  /// Voxels known in both with different log-odds.
  std::size_t value_mismatches = 0;
};

inline Agreement Compare(const VoxelSets& a, const VoxelSets& b) {
  Agreement r;
  r.occupied_jaccard = Jaccard(a.occupied, b.occupied);
  r.free_jaccard = Jaccard(a.free, b.free);
  r.occupied_a = a.occupied.size();
  r.occupied_b = b.occupied.size();
  r.free_a = a.free.size();
  r.free_b = b.free.size();
  for (const auto& [key, value] : a.log_odds) {
    const auto it = b.log_odds.find(key);
    if (it != b.log_odds.end() && it->second != value) ++r.value_mismatches;
  }
  return r;
}

}  // namespace rover::mapping::testing

#endif  // ROVER_TESTS_MAPPING_SUBMAP_SUBMAP_TEST_SCENE_H_
