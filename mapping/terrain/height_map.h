#ifndef ROVER_MAPPING_TERRAIN_HEIGHT_MAP_H_
#define ROVER_MAPPING_TERRAIN_HEIGHT_MAP_H_

// The 2.5D height map of one depth image (thesis section 5.1.1): a
// gravity-aligned top-down grid (5 cm) around the camera whose cells hold
// the mean height of the points falling into them. The step classifier
// works on it; it is rebuilt for every depth image, so that the camera's
// viewpoint (needed for the error-adaptive threshold) is still known.

#include <cstdint>
#include <vector>

#include <Eigen/Geometry>

#include "mapping/depth/depth_image.h"

namespace rover::mapping {

struct HeightMapOptions {
  double resolution_m = 0.05;
  /// The grid spans +-half_extent_m around the camera in x and y.
  double half_extent_m = 6.0;
  /// Cells with fewer points count as empty: at the far end of stereo
  /// range a cell holds a handful of points, and one bad match among one or
  /// two would make its mean a step that is not there.
  uint32_t min_points = 3;
  /// Drop spikes: a cell that lies more than `spike_tolerance_m` off the
  /// median of its 8 neighbours (at least 3 with data) while fewer than 2
  /// of them are within that tolerance of it. A few wrong matches that land
  /// together in one cell (a horizon mismatch, say) float it half a metre
  /// above its neighbours, and as a lone spike it would make a step
  /// obstacle of every window around it. A real step edge has neighbours
  /// at its own height along the edge, so it stays. (The thesis post-filters
  /// small isolated obstacle hypotheses instead; the effect is the same.)
  /// 0 disables it.
  double spike_tolerance_m = 0.05;

  /// Throws std::invalid_argument "HeightMapOptions.<key>: ...".
  void Validate() const;
};

class HeightMap {
 public:
  /// Cells from the depth image's valid points (too uncertain ones are left
  /// out, as the thesis filters them for all later processing).
  static HeightMap Build(const DepthImage& depth, const Eigen::Isometry3d& T_gravity_cam,
                         const HeightMapOptions& options);

  int cols() const { return cols_; }
  int rows() const { return rows_; }
  double resolution_m() const { return resolution_m_; }
  /// World (gravity-frame) x, y of cell (0, 0)'s lower corner.
  const Eigen::Vector2d& origin_xy() const { return origin_xy_; }

  bool Has(int ix, int iy) const { return count(ix, iy) >= min_points_; }
  uint32_t count(int ix, int iy) const { return counts_[Index(ix, iy)]; }
  /// Mean height of the cell's points (meaningful where Has()).
  double height(int ix, int iy) const { return heights_[Index(ix, iy)]; }
  /// The cell's centre at its mean height, gravity frame.
  Eigen::Vector3d CellPoint(int ix, int iy) const {
    return {origin_xy_.x() + (ix + 0.5) * resolution_m_,
            origin_xy_.y() + (iy + 0.5) * resolution_m_, height(ix, iy)};
  }
  /// Cell of a gravity-frame point; false outside the grid.
  bool CellOf(const Eigen::Vector3d& p, int* ix, int* iy) const;

 private:
  void RemoveSpikes(double tolerance_m);
  std::size_t Index(int ix, int iy) const {
    return static_cast<std::size_t>(iy) * static_cast<std::size_t>(cols_) +
           static_cast<std::size_t>(ix);
  }

  int cols_ = 0;
  int rows_ = 0;
  double resolution_m_ = 0.05;
  Eigen::Vector2d origin_xy_ = Eigen::Vector2d::Zero();
  uint32_t min_points_ = 1;
  std::vector<uint32_t> counts_;
  std::vector<double> heights_;
};

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_TERRAIN_HEIGHT_MAP_H_
