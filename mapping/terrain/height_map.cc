#include "mapping/terrain/height_map.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace rover::mapping {

void HeightMapOptions::Validate() const {
  if (!(std::isfinite(resolution_m) && resolution_m > 0.0)) {
    throw std::invalid_argument("HeightMapOptions.resolution_m: expected > 0, found " +
                                std::to_string(resolution_m));
  }
  if (!(std::isfinite(half_extent_m) && half_extent_m >= resolution_m)) {
    throw std::invalid_argument("HeightMapOptions.half_extent_m: expected >= resolution_m, found " +
                                std::to_string(half_extent_m));
  }
}

bool HeightMap::CellOf(const Eigen::Vector3d& p, int* ix, int* iy) const {
  const double fx = std::floor((p.x() - origin_xy_.x()) / resolution_m_);
  const double fy = std::floor((p.y() - origin_xy_.y()) / resolution_m_);
  if (!(fx >= 0.0 && fy >= 0.0 && fx < cols_ && fy < rows_)) return false;
  *ix = static_cast<int>(fx);
  *iy = static_cast<int>(fy);
  return true;
}

HeightMap HeightMap::Build(const DepthImage& depth, const Eigen::Isometry3d& T_gravity_cam,
                           const HeightMapOptions& options) {
  options.Validate();
  HeightMap map;
  map.resolution_m_ = options.resolution_m;
  const int half_cells = static_cast<int>(std::ceil(options.half_extent_m / options.resolution_m));
  map.cols_ = map.rows_ = 2 * half_cells;
  // Cell borders on multiples of the resolution, so that maps of
  // consecutive images line up cell for cell.
  const Eigen::Vector2d camera = T_gravity_cam.translation().head<2>();
  map.origin_xy_ = {
      (std::floor(camera.x() / options.resolution_m) - half_cells) * options.resolution_m,
      (std::floor(camera.y() / options.resolution_m) - half_cells) * options.resolution_m};
  const std::size_t n = static_cast<std::size_t>(map.cols_) * static_cast<std::size_t>(map.rows_);
  map.counts_.assign(n, 0);
  map.heights_.assign(n, 0.0);
  for (int v = 0; v < depth.height(); ++v) {
    for (int u = 0; u < depth.width(); ++u) {
      if (depth.state(u, v) != DepthState::kValid) continue;
      const Eigen::Vector3d p = T_gravity_cam * depth.point(u, v).cast<double>();
      int ix = 0, iy = 0;
      if (!map.CellOf(p, &ix, &iy)) continue;
      const std::size_t i = map.Index(ix, iy);
      // Running mean: no second pass, no extra buffer.
      ++map.counts_[i];
      map.heights_[i] += (p.z() - map.heights_[i]) / map.counts_[i];
    }
  }
  return map;
}

}  // namespace rover::mapping
