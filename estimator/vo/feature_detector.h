#ifndef ROVER_ESTIMATOR_VO_FEATURE_DETECTOR_H_
#define ROVER_ESTIMATOR_VO_FEATURE_DETECTOR_H_

// FAST corners with grid bucketing: the image is cut into cells and each cell
// keeps at most `max_per_cell` of its strongest corners, so features spread
// over the whole image instead of clustering on the most textured patch.
// Cells that already hold tracked features get correspondingly fewer new ones.
// Deterministic: ties in corner response are broken by position.

#include <opencv2/core.hpp>

#include <vector>

namespace rover::estimator::vo {

struct FeatureDetectorOptions {
  int cell_size_px = 48;         ///< side of a square bucket
  int max_per_cell = 3;          ///< features kept per bucket (including existing ones)
  int fast_threshold = 20;       ///< FAST intensity threshold
  int min_fast_threshold = 7;    ///< a cell with no corner is retried down to this threshold
  int border_px = 12;            ///< no feature closer than this to the image edge
  double min_distance_px = 8.0;  ///< minimum distance to any other (new or existing) feature
};

class FeatureDetector {
 public:
  explicit FeatureDetector(const FeatureDetectorOptions& options = {}) : options_(options) {}

  /// Detects new features in an 8-bit grey image, avoiding `existing` ones.
  /// An empty, non-CV_8UC1 or textureless image yields no features.
  std::vector<cv::Point2f> Detect(const cv::Mat& image,
                                  const std::vector<cv::Point2f>& existing = {}) const;

  const FeatureDetectorOptions& options() const { return options_; }

 private:
  FeatureDetectorOptions options_;
};

}  // namespace rover::estimator::vo

#endif  // ROVER_ESTIMATOR_VO_FEATURE_DETECTOR_H_
