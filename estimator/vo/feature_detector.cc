#include "estimator/vo/feature_detector.h"

#include <opencv2/features2d.hpp>

#include <algorithm>
#include <cmath>

namespace rover::estimator::vo {
namespace {

bool StrongerFirst(const cv::KeyPoint& a, const cv::KeyPoint& b) {
  if (a.response != b.response) return a.response > b.response;
  if (a.pt.y != b.pt.y) return a.pt.y < b.pt.y;
  return a.pt.x < b.pt.x;
}

}  // namespace

std::vector<cv::Point2f> FeatureDetector::Detect(const cv::Mat& image,
                                                 const std::vector<cv::Point2f>& existing) const {
  std::vector<cv::Point2f> out;
  const int cell = std::max(options_.cell_size_px, 8);
  if (image.empty() || image.type() != CV_8UC1 || image.cols < cell || image.rows < cell) {
    return out;
  }
  const int cols = (image.cols + cell - 1) / cell;
  const int rows = (image.rows + cell - 1) / cell;
  const auto n_cells = static_cast<size_t>(cols * rows);
  const auto cell_of = [&](const cv::Point2f& p) {
    const int cx = std::clamp(static_cast<int>(p.x) / cell, 0, cols - 1);
    const int cy = std::clamp(static_cast<int>(p.y) / cell, 0, rows - 1);
    return static_cast<size_t>(cy * cols + cx);
  };
  std::vector<int> count(n_cells, 0);
  std::vector<cv::Point2f> taken = existing;
  for (const auto& p : existing) ++count[cell_of(p)];

  const float min_d2 = static_cast<float>(options_.min_distance_px * options_.min_distance_px);
  const auto far_enough = [&](const cv::Point2f& p) {
    for (const auto& q : taken) {
      const cv::Point2f d = p - q;
      if (d.dot(d) < min_d2) return false;
    }
    return true;
  };
  const auto inside = [&](const cv::Point2f& p) {
    const auto b = static_cast<float>(options_.border_px);
    return p.x >= b && p.y >= b && p.x < static_cast<float>(image.cols) - b &&
           p.y < static_cast<float>(image.rows) - b;
  };

  // One FAST pass over the whole image, then corners go to their buckets.
  // Buckets left empty are retried with a lower threshold on their own patch.
  std::vector<std::vector<cv::KeyPoint>> buckets(n_cells);
  std::vector<cv::KeyPoint> keypoints;
  cv::FAST(image, keypoints, options_.fast_threshold, true);
  for (const auto& k : keypoints) {
    if (inside(k.pt)) buckets[cell_of(k.pt)].push_back(k);
  }
  for (int cy = 0; cy < rows; ++cy) {
    for (int cx = 0; cx < cols; ++cx) {
      const auto c = static_cast<size_t>(cy * cols + cx);
      if (count[c] >= options_.max_per_cell) continue;
      auto& bucket = buckets[c];
      if (bucket.empty() && options_.min_fast_threshold < options_.fast_threshold) {
        const cv::Rect roi =
            cv::Rect(cx * cell, cy * cell, cell, cell) & cv::Rect(0, 0, image.cols, image.rows);
        std::vector<cv::KeyPoint> local;
        cv::FAST(image(roi), local, options_.min_fast_threshold, true);
        for (auto& k : local) {
          k.pt += cv::Point2f(static_cast<float>(roi.x), static_cast<float>(roi.y));
          if (inside(k.pt)) bucket.push_back(k);
        }
      }
      std::sort(bucket.begin(), bucket.end(), StrongerFirst);
      for (const auto& k : bucket) {
        if (count[c] >= options_.max_per_cell) break;
        if (!far_enough(k.pt)) continue;
        out.push_back(k.pt);
        taken.push_back(k.pt);
        ++count[c];
      }
    }
  }
  return out;
}

}  // namespace rover::estimator::vo
