#ifndef ROVER_HIL_SIM_EXPERIMENTS_MAP_EVALUATION_H_
#define ROVER_HIL_SIM_EXPERIMENTS_MAP_EVALUATION_H_

// Quality of a composed map against the simulator's ground truth.
//
// Occupancy (10 cm voxels of the composed OctoMap, world frame):
//  * a voxel is on the surface if the ground-truth terrain passes within
//    `surface_tolerance_m` of the voxel's vertical extent somewhere in its
//    footprint (heights sampled on a 5x5 grid over the cell);
//  * precision = occupied voxels on the surface / occupied voxels;
//  * recall = observed surface columns with an occupied surface voxel /
//    observed surface columns, where a 10 cm column is observed if the map
//    knows (free or occupied) any voxel within `observed_band_m` of the
//    surface there: the camera saw that spot, so the surface should be in
//    the map.
// Voxels near the simulator's tag carriers (posts, other rovers: rendered,
// but not part of the heightfield) are left out of both.
//
// Obstacles (5 cm cells of the simulator's obstacle grid, computed with
// rock_min_height_m = h_max so that only rocks taller than a wheel can
// climb count, plus steps and the top edges of drops):
//  * precision = obstacle-flagged cloud points within `obstacle_radius_m`
//    of a ground-truth obstacle cell or of a tag carrier's footprint (a
//    landmark post is an obstacle too, though not part of the heightfield)
//    / flagged points;
//  * recall = ground-truth obstacle cells with a flagged point within
//    `obstacle_radius_m` / ground-truth obstacle cells that were observed:
//    the map has a point within one cell of it, and the camera saw it from
//    within `obstacle_view_range_m` (horizontal distance, inside the
//    camera's horizontal field of view) at one of the given camera poses,
//    from where stereo resolves it. Stereo error grows with the square of
//    the distance: an obstacle is resolved from a pose when its relief
//    (the rock's height for a rock's cells, else the drop or the step the
//    obstacle rule measured there) exceeds h_max by more than the stereo
//    error of that
//    height difference there (first order, the head's rectified geometry
//    at `pixel_error_px`). A 0.48 m boulder is resolved at 4 m; a rock
//    2.5 cm taller than h_max only within about 1.5 m on the simulator's
//    head, and one only ever glimpsed farther away is not counted against
//    the classifier, which cannot tell it from noise there. The rover has
//    to find the obstacles it comes close to.

#include <cstdint>
#include <vector>

#include <Eigen/Geometry>

#include <octomap/OcTree.h>

#include "hil/sim/render/stereo_camera.h"
#include "hil/sim/world/world.h"
#include "mapping/depth/rectified_stereo.h"
#include "mapping/submap/cloud_point.h"

namespace rover::sim::experiments {

struct MapQualityOptions {
  double surface_tolerance_m = 0.1;
  double observed_band_m = 0.3;
  double obstacle_radius_m = 0.15;
  /// Half-width of the area left out around each tag carrier.
  double carrier_margin_m = 0.3;
  double obstacle_view_range_m = 4.0;
  double camera_half_fov_rad = 0.6;
  /// Stereo matching error per image coordinate (thesis: 0.5 px).
  double pixel_error_px = 0.5;
};

struct MapQuality {
  uint64_t occupied_voxels = 0;
  uint64_t occupied_on_surface = 0;
  uint64_t observed_columns = 0;
  uint64_t observed_columns_hit = 0;
  double map_precision = 0.0;
  double map_recall = 0.0;
  uint64_t obstacle_points = 0;
  uint64_t obstacle_points_true = 0;
  uint64_t truth_obstacle_cells_observed = 0;
  uint64_t truth_obstacle_cells_found = 0;
  double obstacle_precision = 0.0;
  double obstacle_recall = 0.0;
};

/// The simulated head as mapd sees it after rectification.
struct RectifiedHead {
  mapping::RectifiedStereo stereo;
  Eigen::Isometry3d T_body_cam0rect = Eigen::Isometry3d::Identity();
};

/// Rectifies the simulated head's calibration as mapd does. Throws
/// std::invalid_argument if that fails.
RectifiedHead RectifiedHeadOf(const sim::StereoCameraOptions& camera);

/// Scores `map_world` and `cloud_world` (CloudPoint::p_submap_m in world
/// coordinates) against `world` and its obstacle grid `truth` (computed
/// with `rule`).
/// `T_world_cameras` are the rectified left camera's true poses along the
/// mission (for the obstacles' view range; OpenCV axes, z forward), `head`
/// its rectified geometry.
MapQuality EvaluateMap(const sim::World& world, const sim::ObstacleGrid& truth,
                       const sim::ObstacleRuleOptions& rule, const octomap::OcTree& map_world,
                       const mapping::PointCloud& cloud_world,
                       const std::vector<Eigen::Isometry3d>& T_world_cameras,
                       const mapping::RectifiedStereo& head, const MapQualityOptions& options = {});

/// A submap's cloud (submap frame) with the pose of its frame in the world.
struct PlacedCloud {
  Eigen::Isometry3d T_world_submap = Eigen::Isometry3d::Identity();
  const mapping::PointCloud* cloud = nullptr;
};

/// The constant shift of every submap's content in its own frame that best
/// explains the clouds' height errors against the true terrain.
struct ContentShift {
  bool ok = false;         ///< false: too few points on slopes to tell
  double forward_m = 0.0;  ///< along the submap frame's x (the heading at its start)
  double left_m = 0.0;
  double up_m = 0.0;
  uint64_t points = 0;  ///< points in the fit
};

/// A point displaced by s from the surface point it saw reads a height error
/// of about -grad H . s, so over many points on sloped ground (rock flanks,
/// crater rims) least squares recovers s, as forward / left / up in each
/// submap's frame: a stamp offset or an extrinsic error moves content along
/// the heading, a depth bias along the view; the matcher's errors do not
/// show here. Points more than 0.1 m off the surface or on slopes above
/// 45 deg are left out. With the submaps at their true origins this tests
/// the content alone. The fit reads about two thirds of a shift of a few
/// centimetres (the 5 cm cloud voxels and the terrain's grid smooth it).
ContentShift EstimateContentShift(const sim::Heightfield& terrain,
                                  const std::vector<PlacedCloud>& clouds);

}  // namespace rover::sim::experiments

#endif  // ROVER_HIL_SIM_EXPERIMENTS_MAP_EVALUATION_H_
