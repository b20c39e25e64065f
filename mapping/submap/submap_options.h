#ifndef ROVER_MAPPING_SUBMAP_SUBMAP_OPTIONS_H_
#define ROVER_MAPPING_SUBMAP_SUBMAP_OPTIONS_H_

// Parameters of one submap's two representations (thesis section 5.1.2): a
// probabilistic OctoMap voxel space and a voxel-filtered point cloud. The
// defaults are the thesis's: 10 cm voxels with OctoMap's inverse sensor
// model (hit 0.7, miss 0.4) and clamping (0.12 / 0.97, log-odds -2 / 3.5),
// and a 5 cm point cloud.

namespace rover::mapping {

struct SubmapOptions {
  /// Edge of the OctoMap's leaf voxels. Coarser than the cloud: the voxel
  /// space is the expensive representation.
  double octree_resolution_m = 0.1;
  /// Inverse sensor model: probability of a voxel that holds an endpoint...
  double prob_hit = 0.7;
  /// ...and of one a ray passed through.
  double prob_miss = 0.4;
  /// Clamping bounds: they cap the confidence, so that a voxel can still
  /// change state within a few images, and let stable voxels be pruned.
  double clamping_min = 0.12;
  double clamping_max = 0.97;
  /// Edge of the point cloud's voxel-centroid grid.
  double cloud_resolution_m = 0.05;
  /// Pixels beyond stereo range (DepthState::kInfinite) saw nothing up to
  /// infinity, so their ray is free; it is cast only this far, because the
  /// pixel's direction is uncertain and a long ray would clear voxels far
  /// off to the side. 0 disables free space from such pixels.
  double max_free_range_m = 5.0;
  /// Rays per endpoint voxel, at most this cubed: endpoints are grouped
  /// into cells of octree_resolution_m / ray_cells_per_voxel_edge and one
  /// ray is cast to each cell's centroid (FastOctreeInserter). 1 casts one
  /// ray per voxel; more rays cover more of the fan of the pixels' own rays
  /// near the surface, i.e. come closer to casting every pixel, at the cost
  /// of more ray steps.
  int ray_cells_per_voxel_edge = 2;
  /// Valid points farther than this from the camera are treated like
  /// OctoMap's maxrange: free up to max_range_m along their ray, no hit.
  /// They are also left out of the point cloud. 0 means unlimited.
  double max_range_m = 0.0;

  /// Throws std::invalid_argument "SubmapOptions.<key>: expected ..., got ...".
  void Validate() const;
};

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_SUBMAP_SUBMAP_OPTIONS_H_
