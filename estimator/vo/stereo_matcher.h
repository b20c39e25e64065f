#ifndef ROVER_ESTIMATOR_VO_STEREO_MATCHER_H_
#define ROVER_ESTIMATOR_VO_STEREO_MATCHER_H_

// Stereo correspondences on a rectified pair by a normalised cross-correlation
// search along the same rows over the disparity range, refined to sub-pixel by
// a parabola through the correlation peak, and checked for left-right
// consistency (the right patch searched back in the left image must land on
// the original feature). Correspondences are kept only when they lie on
// the same row, have positive disparity and a small depth uncertainty, and
// triangulated in the rectified cam0 frame.
//
// Depth uncertainty from the disparity noise sigma_d: z = f b / d, so
//   sigma_z = z^2 / (f b) * sigma_d.

#include <opencv2/core.hpp>

#include <Eigen/Core>
#include <vector>

#include "estimator/vo/stereo_rectifier.h"

namespace rover::estimator::vo {

struct StereoMatcherOptions {
  int search_window_px = 11;     ///< side of the row-search template (odd)
  int search_row_margin_px = 2;  ///< rows searched above and below
  double max_disparity_px = 120.0;
  double min_ncc = 0.8;              ///< minimum correlation of the row search
  double min_template_stddev = 3.0;  ///< textureless templates are not searched
  double max_row_error_px = 1.0;     ///< |v_left - v_right| bound
  double max_fb_error_px = 1.0;      ///< left -> right -> left round-trip bound [px]
  double min_disparity_px = 1.0;
  double disparity_sigma_px = 0.5;        ///< sigma_d in the depth uncertainty
  double max_depth_sigma_m = 1.0;         ///< drop points with larger sigma_z
  double max_relative_depth_sigma = 0.1;  ///< and with sigma_z / z larger than this
};

/// One triangulated stereo correspondence.
struct StereoPoint {
  int feature_index = -1;  ///< index into the left points passed to Match()
  cv::Point2f left;        ///< rectified left pixel
  cv::Point2f right;       ///< rectified right pixel
  Eigen::Vector3d p_cam0rect = Eigen::Vector3d::Zero();  ///< [m]
  double depth_sigma_m = 0.0;
};

/// Why candidates were dropped (one Match() call).
struct StereoMatchStats {
  int candidates = 0;
  int search_rejected = 0;       ///< textureless, out of the image or weak correlation
  int consistency_rejected = 0;  ///< the left-right check failed
  int row_rejected = 0;
  int disparity_rejected = 0;
  int depth_sigma_rejected = 0;
  int accepted = 0;
};

class StereoMatcher {
 public:
  StereoMatcher(const RectifiedIntrinsics& intrinsics, double baseline_m,
                const StereoMatcherOptions& options = {})
      : intrinsics_(intrinsics), baseline_m_(baseline_m), options_(options) {}

  /// Matches `left_points` of the rectified left image into the rectified right
  /// image. Bad input (empty/mismatched images) yields no points.
  std::vector<StereoPoint> Match(const cv::Mat& left, const cv::Mat& right,
                                 const std::vector<cv::Point2f>& left_points,
                                 StereoMatchStats* stats = nullptr) const;

  /// Triangulates a rectified correspondence (no checks beyond d > 0).
  Eigen::Vector3d Triangulate(const cv::Point2f& left, const cv::Point2f& right) const;
  /// sigma_z for depth z [m].
  double DepthSigma(double depth_m) const;

  const StereoMatcherOptions& options() const { return options_; }

 private:
  RectifiedIntrinsics intrinsics_;
  double baseline_m_;
  StereoMatcherOptions options_;
};

}  // namespace rover::estimator::vo

#endif  // ROVER_ESTIMATOR_VO_STEREO_MATCHER_H_
