#include "mapping/terrain/traversability_grid.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <opencv2/imgproc.hpp>

namespace rover::mapping {

void TraversabilityGridOptions::Validate() const {
  if (!(std::isfinite(resolution_m) && resolution_m > 0.0)) {
    throw std::invalid_argument("TraversabilityGridOptions.resolution_m: expected > 0, found " +
                                std::to_string(resolution_m));
  }
  if (!(std::isfinite(half_extent_m) && half_extent_m >= resolution_m)) {
    throw std::invalid_argument(
        "TraversabilityGridOptions.half_extent_m: expected >= resolution_m, found " +
        std::to_string(half_extent_m));
  }
  if (!(alpha > 0.0 && alpha <= 1.0)) {
    throw std::invalid_argument("TraversabilityGridOptions.alpha: expected in (0, 1], found " +
                                std::to_string(alpha));
  }
  if (!(negative_edge_value > 1.0f)) {
    throw std::invalid_argument(
        "TraversabilityGridOptions.negative_edge_value: expected > 1 (untraversable), found " +
        std::to_string(negative_edge_value));
  }
}

TraversabilityGrid::TraversabilityGrid(const TraversabilityGridOptions& options)
    : options_(options) {
  options_.Validate();
  n_ = 2 * static_cast<int>(std::ceil(options_.half_extent_m / options_.resolution_m));
  values_.assign(static_cast<std::size_t>(n_) * static_cast<std::size_t>(n_), -1.0f);
  scratch_ = values_;
  obstacle_images_.assign(values_.size(), 0);
  obstacle_scratch_ = obstacle_images_;
  origin_cx_ = origin_cy_ = -n_ / 2;
}

Eigen::Vector2d TraversabilityGrid::origin_xy() const {
  return {static_cast<double>(origin_cx_) * options_.resolution_m,
          static_cast<double>(origin_cy_) * options_.resolution_m};
}

bool TraversabilityGrid::Local(long cx, long cy, int* ix, int* iy) const {
  const long lx = cx - origin_cx_;
  const long ly = cy - origin_cy_;
  if (lx < 0 || ly < 0 || lx >= n_ || ly >= n_) return false;
  *ix = static_cast<int>(lx);
  *iy = static_cast<int>(ly);
  return true;
}

void TraversabilityGrid::Recentre(const Eigen::Vector2d& rover_xy) {
  const long cx = static_cast<long>(std::floor(rover_xy.x() / options_.resolution_m)) - n_ / 2;
  const long cy = static_cast<long>(std::floor(rover_xy.y() / options_.resolution_m)) - n_ / 2;
  if (cx == origin_cx_ && cy == origin_cy_) return;
  std::fill(scratch_.begin(), scratch_.end(), -1.0f);
  std::fill(obstacle_scratch_.begin(), obstacle_scratch_.end(), 0);
  for (int iy = 0; iy < n_; ++iy) {
    for (int ix = 0; ix < n_; ++ix) {
      const long gx = origin_cx_ + ix;
      const long gy = origin_cy_ + iy;
      const long nx = gx - cx;
      const long ny = gy - cy;
      if (nx < 0 || ny < 0 || nx >= n_ || ny >= n_) continue;  // scrolled off: forgotten
      const std::size_t from = static_cast<std::size_t>(iy) * static_cast<std::size_t>(n_) +
                               static_cast<std::size_t>(ix);
      const std::size_t to = static_cast<std::size_t>(ny) * static_cast<std::size_t>(n_) +
                             static_cast<std::size_t>(nx);
      scratch_[to] = values_[from];
      obstacle_scratch_[to] = obstacle_images_[from];
    }
  }
  values_.swap(scratch_);
  obstacle_images_.swap(obstacle_scratch_);
  origin_cx_ = cx;
  origin_cy_ = cy;
}

void TraversabilityGrid::Blend(long cx, long cy, float observation) {
  int ix = 0, iy = 0;
  if (!Local(cx, cy, &ix, &iy)) return;
  float& v = values_[static_cast<std::size_t>(iy) * static_cast<std::size_t>(n_) +
                     static_cast<std::size_t>(ix)];
  const auto a = static_cast<float>(options_.alpha);
  v = v < 0.0f ? observation : (1.0f - a) * v + a * observation;
}

void TraversabilityGrid::Add(const StepGrid& steps, const std::vector<NegativeEdge>& edges) {
  const double r = options_.resolution_m;
  for (int iy = 0; iy < steps.rows; ++iy) {
    for (int ix = 0; ix < steps.cols; ++ix) {
      if (!steps.Known(ix, iy)) continue;
      const double x = steps.origin_xy.x() + (ix + 0.5) * steps.resolution_m;
      const double y = steps.origin_xy.y() + (iy + 0.5) * steps.resolution_m;
      Blend(static_cast<long>(std::floor(x / r)), static_cast<long>(std::floor(y / r)),
            steps.at(ix, iy));
    }
  }
  for (const NegativeEdge& e : edges) {
    // An edge is a hard fact about the terrain, not a noisy estimate: set it.
    int ix = 0, iy = 0;
    if (!Local(static_cast<long>(std::floor(e.q_gravity.x() / r)),
               static_cast<long>(std::floor(e.q_gravity.y() / r)), &ix, &iy)) {
      continue;
    }
    float& v = values_[static_cast<std::size_t>(iy) * static_cast<std::size_t>(n_) +
                       static_cast<std::size_t>(ix)];
    v = std::max(v, options_.negative_edge_value);
  }
}

void TraversabilityGrid::CountObstacles(const ObstacleCells& cells) {
  const double r = options_.resolution_m;
  for (int iy = 0; iy < cells.rows; ++iy) {
    const uint8_t* row = cells.mask.ptr<uint8_t>(iy);
    for (int ix = 0; ix < cells.cols; ++ix) {
      if (row[ix] == 0) continue;
      const double x = cells.origin_xy.x() + (ix + 0.5) * cells.resolution_m;
      const double y = cells.origin_xy.y() + (iy + 0.5) * cells.resolution_m;
      int lx = 0, ly = 0;
      if (!Local(static_cast<long>(std::floor(x / r)), static_cast<long>(std::floor(y / r)), &lx,
                 &ly)) {
        continue;
      }
      uint8_t& n = obstacle_images_[static_cast<std::size_t>(ly) * static_cast<std::size_t>(n_) +
                                    static_cast<std::size_t>(lx)];
      if (n < 255) ++n;
    }
  }
}

int TraversabilityGrid::ObstacleImages(const Eigen::Vector2d& xy) const {
  int ix = 0, iy = 0;
  if (!Local(static_cast<long>(std::floor(xy.x() / options_.resolution_m)),
             static_cast<long>(std::floor(xy.y() / options_.resolution_m)), &ix, &iy)) {
    return 0;
  }
  return obstacle_images_[static_cast<std::size_t>(iy) * static_cast<std::size_t>(n_) +
                          static_cast<std::size_t>(ix)];
}

void TraversabilityGrid::KeepConfirmed(int min_images, ObstacleCells* cells) {
  const int labels = cv::connectedComponents(cells->mask, labels_, 8, CV_32S);
  confirmed_.assign(static_cast<std::size_t>(labels), 0);
  const auto cell_images = [&](int ix, int iy) {
    return ObstacleImages({cells->origin_xy.x() + (ix + 0.5) * cells->resolution_m,
                           cells->origin_xy.y() + (iy + 0.5) * cells->resolution_m});
  };
  for (int iy = 0; iy < cells->rows; ++iy) {
    const int32_t* label = labels_.ptr<int32_t>(iy);
    for (int ix = 0; ix < cells->cols; ++ix) {
      uint8_t& confirmed = confirmed_[static_cast<std::size_t>(label[ix])];
      if (label[ix] > 0 && confirmed == 0 && cell_images(ix, iy) >= min_images) confirmed = 1;
    }
  }
  for (int iy = 0; iy < cells->rows; ++iy) {
    const int32_t* label = labels_.ptr<int32_t>(iy);
    uint8_t* row = cells->mask.ptr<uint8_t>(iy);
    for (int ix = 0; ix < cells->cols; ++ix) {
      if (confirmed_[static_cast<std::size_t>(label[ix])] == 0) row[ix] = 0;
    }
  }
}

float TraversabilityGrid::ValueAt(const Eigen::Vector2d& xy) const {
  int ix = 0, iy = 0;
  if (!Local(static_cast<long>(std::floor(xy.x() / options_.resolution_m)),
             static_cast<long>(std::floor(xy.y() / options_.resolution_m)), &ix, &iy)) {
    return -1.0f;
  }
  return value(ix, iy);
}

}  // namespace rover::mapping
