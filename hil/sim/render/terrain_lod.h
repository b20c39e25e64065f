#ifndef ROVER_HIL_SIM_RENDER_TERRAIN_LOD_H_
#define ROVER_HIL_SIM_RENDER_TERRAIN_LOD_H_

// Level of detail for the terrain mesh: a quadtree of square patches over
// the heightfield grid. Every patch, whatever its level, is drawn as the same
// grid of kPatchQuads x kPatchQuads quads; a patch of level L covers
// kPatchQuads * 2^L cells and samples every 2^L-th height.
//
// The rasteriser's cost is per triangle, so the mesh is only as fine as the
// image needs: a patch is split while it is nearer than
// full_resolution_distance_m or while its geometric error (largest height
// difference between its coarse mesh and the full-resolution one) would show
// as more than max_error_px in the image. Flat ground coarsens quickly, rocks
// and crater rims keep their detail.
//
// Cracks between neighbours of different levels are closed in the vertex
// shader: along an edge that borders a coarser patch, heights are
// interpolated between that patch's samples (edge_stride_cells below).

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

#include "hil/sim/world/world.h"

namespace rover::sim {

/// One patch to draw.
struct TerrainPatch {
  int ix0 = 0;  ///< first cell of the patch (grid index)
  int iy0 = 0;
  int level = 0;         ///< sample stride is 2^level cells
  int stride_cells = 1;  ///< 2^level
  /// Stride of the coarser neighbour along the -x, +x, -y, +y edges, or this
  /// patch's own stride where the neighbour is not coarser.
  std::array<int, 4> edge_stride_cells = {1, 1, 1, 1};
  Eigen::Vector3d min_world = Eigen::Vector3d::Zero();  ///< bounding box
  Eigen::Vector3d max_world = Eigen::Vector3d::Zero();
  double distance_m = 0.0;  ///< from the eye to the bounding box
  double error_m = 0.0;     ///< geometric error of this level against full resolution
};

/// How fine the mesh must be.
struct TerrainLodParams {
  double full_resolution_distance_m = 6.0;
  double max_error_px = 2.0;
  double focal_px = 460.0;  ///< converts metres at a distance to pixels
};

class TerrainQuadtree {
 public:
  /// Quads per patch side, at every level. Small patches let the mesh refine
  /// only around what needs it (a rock, a crater rim); all visible patches go
  /// out in one instanced draw, so their number costs little.
  static constexpr int kPatchQuads = 4;

  /// Precomputes per-patch height bounds and geometric errors at every level
  /// (about 0.5 s for a 2561 x 2561 grid).
  explicit TerrainQuadtree(const Heightfield& terrain);

  /// Chooses the patches for an eye position. The result covers the whole
  /// grid once, sorted near to far (so early depth rejection saves shading).
  std::vector<TerrainPatch> Select(const Eigen::Vector3d& eye_world,
                                   const TerrainLodParams& params) const;

  int levels() const { return static_cast<int>(levels_.size()); }

 private:
  struct Level {
    int nx = 0;  ///< patches along x at this level
    int ny = 0;
    std::vector<float> z_min;
    std::vector<float> z_max;
    std::vector<float> error_m;
  };
  void SelectRecursive(int level, int px, int py, const Eigen::Vector3d& eye,
                       const TerrainLodParams& params, std::vector<TerrainPatch>* out) const;
  TerrainPatch MakePatch(int level, int px, int py, const Eigen::Vector3d& eye) const;
  void ComputeErrors(const Heightfield& terrain, int level);

  int cols_ = 0;
  int rows_ = 0;
  double resolution_m_ = 0.0;
  Eigen::Vector2d origin_xy_ = Eigen::Vector2d::Zero();
  std::vector<Level> levels_;  ///< [0] finest; back() is a single root patch
};

}  // namespace rover::sim

#endif  // ROVER_HIL_SIM_RENDER_TERRAIN_LOD_H_
