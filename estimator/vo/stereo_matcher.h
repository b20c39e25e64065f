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
// The search is coarse-to-fine, because rectification leaves the match within
// a pixel or so of the feature's row: the feature's own row is scanned over the
// whole disparity range, and only its strongest peaks are then climbed over
// the +-search_row_margin_px band (the NCC surface of a blurred image is smooth
// over a pixel, so the band's best peak lies uphill of a row peak). On EuRoC
// this keeps ~99.5 % of the exhaustive search's matches; the rest are edges,
// whose NCC is a ridge with near-equal maxima along it. The right -> left
// check is done the same way. With a disparity prior per feature
// (e.g. from the previous frame) only +-radius around it is searched; the
// right -> left check still spans the whole disparity range, since it is what
// rejects a wrong patch that happens to correlate inside a wrong window.
//
// Scores are exact: pixels enter as integers, so the sums of the correlation
// are exact in float (for windows up to 31 px) and the NCC is formed in
// double. The result is thus deterministic and the same with SSE2, NEON or
// without SIMD.
//
// Depth uncertainty from the disparity noise sigma_d: z = f b / d, so
//   sigma_z = z^2 / (f b) * sigma_d.

#include <opencv2/core.hpp>

#include <Eigen/Core>
#include <vector>

#include "core/calib/stereo_rectifier.h"

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
  /// Peaks of the feature's row refined over the row band: the best few (1-8),
  /// down to min_ncc - row_peak_ncc_slack (a match a row off scores lower on
  /// the feature's row than at its own).
  int max_row_peaks = 3;
  double row_peak_ncc_slack = 0.3;
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
  int prior_searches = 0;  ///< candidates searched only around their disparity prior
};

class StereoMatcher {
 public:
  StereoMatcher(const calib::RectifiedIntrinsics& intrinsics, double baseline_m,
                const StereoMatcherOptions& options = {})
      : intrinsics_(intrinsics), baseline_m_(baseline_m), options_(options) {}

  /// Half-width of the disparity window searched around a prior: a few
  /// pixels of disparity change between frames (at 1 m, 5 cm closer changes
  /// f b / z by ~2.5 px on EuRoC).
  static constexpr double kDefaultPriorRadiusPx = 4.0;

  /// Matches `left_points` of the rectified left image into the rectified right
  /// image. Bad input (empty/mismatched images, a prior vector whose size
  /// differs from `left_points`) yields no points.
  ///
  /// `disparity_prior_px`, if given, holds an expected disparity per left
  /// point [px]: the left -> right search then only considers disparities
  /// within +-prior_radius_px of it, and rejects a point whose correlation
  /// still rises at the edge of that window (the prior is off). The
  /// right -> left check stays a full search. A negative or non-finite prior
  /// means unknown: full search.
  std::vector<StereoPoint> Match(const cv::Mat& left, const cv::Mat& right,
                                 const std::vector<cv::Point2f>& left_points,
                                 StereoMatchStats* stats = nullptr,
                                 const std::vector<float>* disparity_prior_px = nullptr,
                                 double prior_radius_px = kDefaultPriorRadiusPx) const;

  /// Triangulates a rectified correspondence (no checks beyond d > 0).
  Eigen::Vector3d Triangulate(const cv::Point2f& left, const cv::Point2f& right) const;
  /// sigma_z for depth z [m].
  double DepthSigma(double depth_m) const;

  const StereoMatcherOptions& options() const { return options_; }

 private:
  calib::RectifiedIntrinsics intrinsics_;
  double baseline_m_;
  StereoMatcherOptions options_;
};

}  // namespace rover::estimator::vo

#endif  // ROVER_ESTIMATOR_VO_STEREO_MATCHER_H_
