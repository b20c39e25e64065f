#include "mapping/terrain/height_map.h"

#include <algorithm>
#include <array>
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
  if (!(spike_tolerance_m >= 0.0)) {
    throw std::invalid_argument("HeightMapOptions.spike_tolerance_m: expected >= 0, found " +
                                std::to_string(spike_tolerance_m));
  }
  if (min_points < 1) {
    throw std::invalid_argument("HeightMapOptions.min_points: expected >= 1, found 0");
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
  map.min_points_ = options.min_points;
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
  if (options.spike_tolerance_m > 0.0) map.RemoveSpikes(options.spike_tolerance_m);
  return map;
}

void HeightMap::RemoveSpikes(double tolerance_m) {
  std::vector<std::size_t> spikes;
  std::array<double, 8> neighbours{};
  for (int iy = 0; iy < rows_; ++iy) {
    for (int ix = 0; ix < cols_; ++ix) {
      if (!Has(ix, iy)) continue;
      const double h = height(ix, iy);
      std::size_t n = 0;
      int agree = 0;
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const int x = ix + dx;
          const int y = iy + dy;
          if ((dx == 0 && dy == 0) || x < 0 || y < 0 || x >= cols_ || y >= rows_ || !Has(x, y)) {
            continue;
          }
          neighbours[n++] = height(x, y);
          if (std::abs(height(x, y) - h) <= tolerance_m) ++agree;
        }
      }
      if (n < 3 || agree >= 2) continue;
      const auto mid = neighbours.begin() + static_cast<std::ptrdiff_t>(n / 2);
      std::nth_element(neighbours.begin(), mid,
                       neighbours.begin() + static_cast<std::ptrdiff_t>(n));
      if (std::abs(h - *mid) > tolerance_m) spikes.push_back(Index(ix, iy));
    }
  }
  // Judged on the unfiltered map, removed together: removing one spike
  // must not change the verdict on its neighbours.
  for (const std::size_t i : spikes) counts_[i] = 0;
}

}  // namespace rover::mapping
