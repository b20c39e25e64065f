#ifndef ROVER_MAPPING_LOOP_SUBMAP_MATCH_DATA_H_
#define ROVER_MAPPING_LOOP_SUBMAP_MATCH_DATA_H_

// What the submap matcher needs of one finished submap, computed once
// (thesis section 6.1.1) and immutable afterwards, so that one instance can
// be shared (std::shared_ptr<const SubmapMatchData>) by the pairing and any
// number of concurrent Match() calls:
//   keypoints  the obstacle points through a 0.1 m voxel grid (centroids),
//              minus those too close to unknown space: the share of known
//              voxels of the OctoMap in the descriptor's support sphere must
//              reach min_known_ratio (0.8), or the descriptor would read
//              unobserved space as free;
//   descriptors and their index (gravity_descriptor.h, point_kd_tree.h);
//   the cloud  with normals and its k-d tree (ICP target), and a coarser
//              subsample (ICP source);
//   the xy bounding box of the obstacle points (pairing, eq. 6.1);
//   suitability: at least 1000 points and 20 obstacle points, and
//              optionally the keypoints spread beyond a line (off by
//              default, see min_keypoints_off_line), else the submap is
//              never paired.
//
// Normals point to the observed side: PCA leaves their sign open, and
// gravity alone (n_z >= 0) cannot tell the front of a rock from its back.
// The voxel space can: the side a camera looked from is free. A normal whose
// tip lies in unknown or occupied space while its tail lies in free space is
// flipped. The ICP then refuses to pair a rock's front seen from one submap
// with its back seen from the other (opposite-direction revisits).
//
// Unknown space below the surface: stereo never sees under the ground, so
// half of the sphere around a ground-level keypoint is unknown however well
// the place was seen. That is not unknown space the descriptor could mistake
// for free (its points stop at the surface), so by default an unknown voxel
// below an occupied one in the same column counts as known (solid).

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <octomap/OcTree.h>
#include <Eigen/Core>
#include <Eigen/Geometry>

#include "core/config/config.h"
#include "mapping/loop/gravity_descriptor.h"
#include "mapping/loop/point_kd_tree.h"
#include "mapping/submap/cloud_point.h"

namespace rover::mapping {

struct SubmapMatchDataOptions {
  /// Voxel grid that turns obstacle points into keypoints.
  double keypoint_voxel_m = 0.1;
  /// Share of known voxels required in the descriptor's support sphere
  /// (thesis: 0.8). 0 keeps every keypoint.
  double min_known_ratio = 0.8;
  /// Count unknown voxels under an occupied one (same column) as known.
  bool solid_below_surface = true;
  /// Neighbourhood of the PCA normals.
  double normal_radius_m = 0.15;
  /// Flip normals towards the free side (see above); off: all point up.
  bool orient_normals_to_free_space = true;
  /// Suitability (thesis section 6.1.1).
  int min_points = 1000;
  int min_obstacle_points = 20;
  double off_line_distance_m = 0.5;
  /// 0 by default: keypoints along a line no longer make a submap
  /// unsuitable, as the matcher takes such matches on when the ICP over the
  /// whole cloud is well conditioned (SubmapMatcherOptions::
  /// line_hypotheses_need_icp); on a drive through sparse rocks most submaps
  /// see a few rocks in a row.
  int min_keypoints_off_line = 0;
  /// Random line samples of the spread check (all pairs when fewer).
  int line_samples = 2000;
  /// Voxel grid of the ICP source subsample.
  double icp_voxel_m = 0.1;
  GravityDescriptorOptions descriptor;
  DescriptorSearch descriptor_search = DescriptorSearch::kBruteForce;
  /// Seeds the line-spread RANSAC.
  uint64_t seed = 1;

  /// Throws std::invalid_argument "SubmapMatchDataOptions.<key>: ...".
  void Validate() const;
  /// Keys as the fields; descriptor is a child map, descriptor_search is
  /// kdtree | brute_force.
  static SubmapMatchDataOptions Load(const ConfigNode& node);
};

/// Why a submap can or cannot be matched.
enum class SubmapSuitability {
  kSuitable,
  kTooFewPoints,
  kTooFewObstaclePoints,
  kKeypointsOnALine,
};

/// "suitable", "too few points", ...
const char* ToString(SubmapSuitability s);

class SubmapMatchData {
 public:
  /// Computes everything from a finished submap's cloud (submap frame) and
  /// voxel space. Throws std::invalid_argument for invalid options or a
  /// non-finite cloud point (naming its index).
  SubmapMatchData(const PointCloud& cloud, const octomap::OcTree& octree,
                  const SubmapMatchDataOptions& options);
  SubmapMatchData(const SubmapMatchData&) = delete;
  SubmapMatchData& operator=(const SubmapMatchData&) = delete;

  /// Convenience: the same, shared.
  static std::shared_ptr<const SubmapMatchData> Build(const PointCloud& cloud,
                                                      const octomap::OcTree& octree,
                                                      const SubmapMatchDataOptions& options);

  /// Everything but the options as bytes, for a spill file that the same
  /// build reads back (native byte order, no version: not an exchange
  /// format). The k-d trees are not stored; Deserialize rebuilds them, and
  /// as they keep the points' order, matches against the copy are the same.
  std::string Serialize() const;
  /// Reads what Serialize() wrote; `options` must be those the data were
  /// built with. Throws std::runtime_error saying what is wrong with a
  /// short, long or inconsistent `bytes`.
  static std::shared_ptr<const SubmapMatchData> Deserialize(std::string_view bytes,
                                                            const SubmapMatchDataOptions& options);

  bool suitable() const { return suitability_ == SubmapSuitability::kSuitable; }
  SubmapSuitability suitability() const { return suitability_; }
  /// Human-readable verdict with the counts behind it.
  const std::string& suitability_reason() const { return reason_; }

  /// Keypoints (submap frame) that kept a descriptor, and per keypoint: its
  /// descriptor row, yaw reference and its strength.
  const std::vector<Eigen::Vector3f>& keypoints() const { return keypoints_; }
  const DescriptorIndex& descriptors() const { return descriptors_; }
  const std::vector<float>& yaw_reference_rad() const { return yaw_reference_rad_; }
  const std::vector<float>& yaw_reference_strength() const { return yaw_reference_strength_; }

  /// The full cloud, its normals (towards free space) and obstacle flags.
  const PointKdTree& cloud() const { return cloud_; }
  const std::vector<Eigen::Vector3f>& normals() const { return normals_; }
  const std::vector<uint8_t>& obstacle() const { return obstacle_; }
  /// The cloud through icp_voxel_m (centroids), with the normal and the
  /// obstacle flag of the nearest cloud point.
  const std::vector<Eigen::Vector3f>& icp_points() const { return icp_points_; }
  const std::vector<Eigen::Vector3f>& icp_normals() const { return icp_normals_; }
  const std::vector<uint8_t>& icp_obstacle() const { return icp_obstacle_; }

  /// Axis-aligned xy box of the obstacle points (submap frame); empty if
  /// there are none.
  const Eigen::AlignedBox2d& obstacle_box_xy() const { return obstacle_box_xy_; }

  int point_count() const { return static_cast<int>(cloud_.size()); }
  int obstacle_point_count() const { return obstacle_points_; }
  /// Keypoints from the voxel grid, before the known-space filter.
  int keypoints_before_filter() const { return keypoints_before_filter_; }
  /// Dropped for unknown space, and for too small a support.
  int keypoints_dropped_unknown() const { return keypoints_dropped_unknown_; }
  int keypoints_dropped_support() const { return keypoints_dropped_support_; }
  /// Keypoints farther than off_line_distance_m from the best line.
  int keypoints_off_line() const { return keypoints_off_line_; }
  /// Wall time of the constructor.
  double build_ms() const { return build_ms_; }
  const SubmapMatchDataOptions& options() const { return options_; }

 private:
  SubmapMatchData() = default;  // Deserialize fills it

  SubmapMatchDataOptions options_;
  SubmapSuitability suitability_ = SubmapSuitability::kSuitable;
  std::string reason_;
  std::vector<Eigen::Vector3f> keypoints_;
  DescriptorIndex descriptors_;
  std::vector<float> yaw_reference_rad_;
  std::vector<float> yaw_reference_strength_;
  PointKdTree cloud_;
  std::vector<Eigen::Vector3f> normals_;
  std::vector<uint8_t> obstacle_;
  std::vector<Eigen::Vector3f> icp_points_;
  std::vector<Eigen::Vector3f> icp_normals_;
  std::vector<uint8_t> icp_obstacle_;
  Eigen::AlignedBox2d obstacle_box_xy_;
  int obstacle_points_ = 0;
  int keypoints_before_filter_ = 0;
  int keypoints_dropped_unknown_ = 0;
  int keypoints_dropped_support_ = 0;
  int keypoints_off_line_ = 0;
  double build_ms_ = 0.0;
};

/// Centroids of `points` per voxel of edge `voxel_m` (sorted by voxel
/// index, so the result does not depend on the input order).
std::vector<Eigen::Vector3f> VoxelCentroids(const std::vector<Eigen::Vector3f>& points,
                                            double voxel_m);

/// Flips each normal whose tip (point + one voxel along it) is not free in
/// `octree` while its tail (point - one voxel) is; `normals` and `points`
/// correspond.
void OrientNormalsToFreeSpace(const octomap::OcTree& octree,
                              const std::vector<Eigen::Vector3f>& points,
                              std::vector<Eigen::Vector3f>* normals);

/// Share of known voxels of `octree` among those whose centres lie within
/// `radius_m` of each query point, with unknown voxels under an occupied one
/// counted as known if `solid_below_surface`.
std::vector<float> KnownRatios(const octomap::OcTree& octree,
                               const std::vector<Eigen::Vector3f>& queries, double radius_m,
                               bool solid_below_surface);

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_LOOP_SUBMAP_MATCH_DATA_H_
