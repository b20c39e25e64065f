#include "mapping/terrain/obstacle_cells.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include <opencv2/imgproc.hpp>

namespace rover::mapping {
namespace {

// Stands in for "no known cell" in the window minimum and maximum.
constexpr float kNoHeight = 1e6f;

}  // namespace

void ObstacleCellOptions::Validate() const {
  if (!(closing_radius_m >= 0.0 && closing_radius_m <= 2.0)) {
    throw std::invalid_argument("ObstacleCellOptions.closing_radius_m: expected 0..2 m, found " +
                                std::to_string(closing_radius_m));
  }
  if (!(std::isfinite(max_raised_region_m) && max_raised_region_m > 0.0)) {
    throw std::invalid_argument("ObstacleCellOptions.max_raised_region_m: expected > 0, found " +
                                std::to_string(max_raised_region_m));
  }
}

bool ObstacleCells::CellOf(const Eigen::Vector3f& p, int* ix, int* iy) const {
  const double fx = std::floor((static_cast<double>(p.x()) - origin_xy.x()) / resolution_m);
  const double fy = std::floor((static_cast<double>(p.y()) - origin_xy.y()) / resolution_m);
  if (!(fx >= 0.0 && fy >= 0.0 && fx < cols && fy < rows)) return false;
  *ix = static_cast<int>(fx);
  *iy = static_cast<int>(fy);
  return true;
}

ObstacleCellMarker::ObstacleCellMarker(const ObstacleCellOptions& options,
                                       const StepClassifierOptions& steps)
    : options_(options), steps_(steps) {
  options_.Validate();
  steps_.Validate();
}

void ObstacleCellMarker::Mark(const StepGrid& steps, const HeightMap& map, ObstacleCells* out) {
  out->cols = steps.cols;
  out->rows = steps.rows;
  out->resolution_m = steps.resolution_m;
  out->origin_xy = steps.origin_xy;
  out->raised_regions = 0;
  out->mask.create(steps.rows, steps.cols, CV_8UC1);
  for (int iy = 0; iy < steps.rows; ++iy) {
    uint8_t* row = out->mask.ptr<uint8_t>(iy);
    for (int ix = 0; ix < steps.cols; ++ix) row[ix] = steps.Obstacle(ix, iy) ? 255 : 0;
  }
  const int radius = static_cast<int>(std::lround(options_.closing_radius_m / steps.resolution_m));
  if (radius > 0) {
    if (disc_.rows != 2 * radius + 1) {
      disc_ =
          cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * radius + 1, 2 * radius + 1));
    }
    cv::morphologyEx(out->mask, out->mask, cv::MORPH_CLOSE, disc_);
  }
  if (options_.fill_raised_regions) FillRaisedRegions(steps, map, out);
}

void ObstacleCellMarker::FillRaisedRegions(const StepGrid& steps, const HeightMap& map,
                                           ObstacleCells* out) {
  const int cols = out->cols;
  const int rows = out->rows;
  // Foot and top of the step window around every cell: the same window
  // ([i - w/2, i - w/2 + w)) the step test took h_diff over.
  heights_low_.create(rows, cols, CV_32FC1);
  heights_high_.create(rows, cols, CV_32FC1);
  free_.create(rows, cols, CV_8UC1);
  for (int iy = 0; iy < rows; ++iy) {
    float* low = heights_low_.ptr<float>(iy);
    float* high = heights_high_.ptr<float>(iy);
    uint8_t* free = free_.ptr<uint8_t>(iy);
    for (int ix = 0; ix < cols; ++ix) {
      const bool known = map.Has(ix, iy);
      const auto h = static_cast<float>(map.height(ix, iy));
      low[ix] = known ? h : kNoHeight;
      high[ix] = known ? h : -kNoHeight;
      free[ix] = known ? 255 : 0;
    }
  }
  // Regions of known cells, joined across single unknown cells: a surface
  // seen at a grazing angle (the far half of a rock's top) is sampled in
  // rows farther apart than a cell, and would fall apart into islands that
  // touch no step.
  cv::morphologyEx(free_, free_, cv::MORPH_CLOSE, cv::Mat::ones(3, 3, CV_8UC1));
  free_.setTo(0, out->mask);
  const int w = steps_.window_cells;
  const cv::Mat window = cv::Mat::ones(w, w, CV_8UC1);
  const cv::Point anchor(w / 2, w / 2);
  cv::erode(heights_low_, foot_, window, anchor);
  cv::dilate(heights_high_, top_, window, anchor);

  const int labels =
      cv::connectedComponentsWithStats(free_, labels_, stats_, centroids_, 4, CV_32S);
  // Per region: 2 until it meets a bounding step, 1 once it has and lies
  // on the upper side of all so far, 0 once it lies on the lower side of
  // one. Above or below by more than that step's own threshold (h_max plus
  // the stereo error there): what the step test could tell from noise. An
  // obstacle cell that is no step itself (a closing's fill), or whose
  // window leaves the region neither clearly above nor below it (noise on
  // the rock's top), says nothing.
  bounded_above_.assign(static_cast<std::size_t>(labels), 2);
  constexpr int kDx[4] = {1, -1, 0, 0};
  constexpr int kDy[4] = {0, 0, 1, -1};
  for (int iy = 0; iy < rows; ++iy) {
    const int32_t* label = labels_.ptr<int32_t>(iy);
    for (int ix = 0; ix < cols; ++ix) {
      if (label[ix] <= 0) continue;
      uint8_t& verdict = bounded_above_[static_cast<std::size_t>(label[ix])];
      if (verdict == 0 || !map.Has(ix, iy)) continue;  // a joining cell has no height
      const auto h = static_cast<float>(map.height(ix, iy));
      for (int k = 0; k < 4 && verdict != 0; ++k) {
        const int nx = ix + kDx[k];
        const int ny = iy + kDy[k];
        if (nx < 0 || ny < 0 || nx >= cols || ny >= rows || !steps.Obstacle(nx, ny)) {
          continue;  // unknown, outside, the region itself or no step
        }
        const float foot = foot_.at<float>(ny, nx);
        const float top = top_.at<float>(ny, nx);
        // The step test's threshold there: h_diff / (h_diff / threshold).
        const float threshold = (top - foot) / steps.at(nx, ny);
        const float above = h - foot;
        const float below = top - h;
        if (above > below && above > threshold) {
          verdict = 1;
        } else if (below > threshold) {
          verdict = 0;
        }
      }
    }
  }
  const int max_cells = static_cast<int>(options_.max_raised_region_m / out->resolution_m);
  bool any = false;
  for (int l = 1; l < labels; ++l) {
    uint8_t& verdict = bounded_above_[static_cast<std::size_t>(l)];
    if (verdict == 1 && (stats_.at<int32_t>(l, cv::CC_STAT_WIDTH) > max_cells ||
                         stats_.at<int32_t>(l, cv::CC_STAT_HEIGHT) > max_cells)) {
      verdict = 0;
    }
    if (verdict == 1) {
      ++out->raised_regions;
      any = true;
    }
  }
  if (!any) return;
  for (int iy = 0; iy < rows; ++iy) {
    const int32_t* label = labels_.ptr<int32_t>(iy);
    uint8_t* obstacle = out->mask.ptr<uint8_t>(iy);
    for (int ix = 0; ix < cols; ++ix) {
      if (label[ix] > 0 && bounded_above_[static_cast<std::size_t>(label[ix])] == 1) {
        obstacle[ix] = 255;
      }
    }
  }
}

}  // namespace rover::mapping
