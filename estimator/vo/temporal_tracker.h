#ifndef ROVER_ESTIMATOR_VO_TEMPORAL_TRACKER_H_
#define ROVER_ESTIMATOR_VO_TEMPORAL_TRACKER_H_

// Tracks features from a reference (keyframe) image into the current image by
// pyramidal KLT, then back again: a track is kept only when the backward track
// lands within `max_fb_error_px` of where it started (forward-backward check)
// and the point stays inside the image.

#include <opencv2/core.hpp>

#include <vector>

namespace rover::estimator::vo {

struct TemporalTrackerOptions {
  /// KLT window side. The tracker is translation-only while a ground patch
  /// seen from a camera pitched down grows and shears by tens of percent
  /// between keyframes half a metre apart; the larger the window, the more
  /// of that warp it averages into the track. A 21 px window gave the VO a
  /// heading drift of +0.004 to +0.014 deg/m, always the same sign, and
  /// 0.18-0.25 % translation RPE on four rendered drives; 11 px gives
  /// -0.007 to +0.003 deg/m and 0.11-0.16 % (estimator/vo/README.md).
  int window_px = 11;
  int pyramid_levels = 3;  ///< levels above the base
  int max_iterations = 30;
  double max_fb_error_px = 0.5;
  int border_px = 2;  ///< tracks closer to the edge are dropped
};

/// Result of one Track() call, index-aligned with the input points.
struct TrackResult {
  std::vector<cv::Point2f> points;     ///< position in the current image
  std::vector<unsigned char> tracked;  ///< 1: track kept
  int lost = 0;                        ///< KLT failed or left the image
  int fb_rejected = 0;                 ///< failed the forward-backward check
  int kept = 0;
};

class TemporalTracker {
 public:
  explicit TemporalTracker(const TemporalTrackerOptions& options = {}) : options_(options) {}

  /// Tracks `ref_points` of `ref` into `cur` (8-bit grey, same size). Bad
  /// input (empty, wrong type or size) yields a result with nothing tracked.
  TrackResult Track(const cv::Mat& ref, const cv::Mat& cur,
                    const std::vector<cv::Point2f>& ref_points) const;

  /// Builds the KLT pyramid (with derivatives) of an 8-bit grey image for
  /// TrackPyramids(), with `window_px` borders and `levels` levels above the
  /// base. Building it once per image saves rebuilding it in every call.
  static void BuildPyramid(const cv::Mat& image, int window_px, int levels,
                           std::vector<cv::Mat>* pyramid);

  /// As Track(), on pyramids from BuildPyramid() (built with a window at
  /// least `window_px` and at least `pyramid_levels` levels), starting each
  /// point at `initial_guess` (index-aligned with ref_points; empty: at its
  /// reference position). Bad input yields nothing tracked.
  TrackResult TrackPyramids(const std::vector<cv::Mat>& ref_pyramid,
                            const std::vector<cv::Mat>& cur_pyramid,
                            const std::vector<cv::Point2f>& ref_points,
                            const std::vector<cv::Point2f>& initial_guess = {}) const;

  const TemporalTrackerOptions& options() const { return options_; }

 private:
  template <typename Image>
  TrackResult TrackImpl(const Image& ref, const Image& cur, cv::Size size,
                        const std::vector<cv::Point2f>& ref_points,
                        const std::vector<cv::Point2f>& initial_guess) const;

  TemporalTrackerOptions options_;
};

}  // namespace rover::estimator::vo

#endif  // ROVER_ESTIMATOR_VO_TEMPORAL_TRACKER_H_
