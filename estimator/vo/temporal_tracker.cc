#include "estimator/vo/temporal_tracker.h"

#include <opencv2/video/tracking.hpp>

#include <cmath>

namespace rover::estimator::vo {

TrackResult TemporalTracker::Track(const cv::Mat& ref, const cv::Mat& cur,
                                   const std::vector<cv::Point2f>& ref_points) const {
  if (ref.empty() || cur.empty() || ref.size() != cur.size() || ref.type() != CV_8UC1 ||
      cur.type() != CV_8UC1) {
    TrackResult out;
    out.points = ref_points;
    out.tracked.assign(ref_points.size(), 0);
    out.lost = static_cast<int>(ref_points.size());
    return out;
  }
  return TrackImpl(ref, cur, cur.size(), ref_points, {});
}

void TemporalTracker::BuildPyramid(const cv::Mat& image, int window_px, int levels,
                                   std::vector<cv::Mat>* pyramid) {
  pyramid->clear();
  if (image.empty() || image.type() != CV_8UC1) return;
  cv::buildOpticalFlowPyramid(image, *pyramid, cv::Size(window_px, window_px), levels, true);
}

TrackResult TemporalTracker::TrackPyramids(const std::vector<cv::Mat>& ref_pyramid,
                                           const std::vector<cv::Mat>& cur_pyramid,
                                           const std::vector<cv::Point2f>& ref_points,
                                           const std::vector<cv::Point2f>& initial_guess) const {
  const bool bad = ref_pyramid.empty() || cur_pyramid.empty() ||
                   ref_pyramid[0].size() != cur_pyramid[0].size() ||
                   (!initial_guess.empty() && initial_guess.size() != ref_points.size());
  if (bad) {
    TrackResult out;
    out.points = ref_points;
    out.tracked.assign(ref_points.size(), 0);
    out.lost = static_cast<int>(ref_points.size());
    return out;
  }
  return TrackImpl(ref_pyramid, cur_pyramid, cur_pyramid[0].size(), ref_points, initial_guess);
}

template <typename Image>
TrackResult TemporalTracker::TrackImpl(const Image& ref, const Image& cur, cv::Size size,
                                       const std::vector<cv::Point2f>& ref_points,
                                       const std::vector<cv::Point2f>& initial_guess) const {
  TrackResult out;
  out.points = initial_guess.empty() ? ref_points : initial_guess;
  out.tracked.assign(ref_points.size(), 0);
  if (ref_points.empty()) return out;
  const cv::Size window(options_.window_px, options_.window_px);
  const cv::TermCriteria term(cv::TermCriteria::COUNT | cv::TermCriteria::EPS,
                              options_.max_iterations, 0.01);
  std::vector<unsigned char> status, back_status;
  std::vector<float> error;
  cv::calcOpticalFlowPyrLK(ref, cur, ref_points, out.points, status, error, window,
                           options_.pyramid_levels, term, cv::OPTFLOW_USE_INITIAL_FLOW);
  std::vector<cv::Point2f> back = ref_points;
  cv::calcOpticalFlowPyrLK(cur, ref, out.points, back, back_status, error, window,
                           options_.pyramid_levels, term, cv::OPTFLOW_USE_INITIAL_FLOW);
  const auto b = static_cast<float>(options_.border_px);
  const auto max_x = static_cast<float>(size.width) - b;
  const auto max_y = static_cast<float>(size.height) - b;
  for (size_t i = 0; i < ref_points.size(); ++i) {
    const cv::Point2f& p = out.points[i];
    if (status[i] == 0 || back_status[i] == 0 || !std::isfinite(p.x) || !std::isfinite(p.y) ||
        p.x < b || p.y < b || p.x >= max_x || p.y >= max_y) {
      ++out.lost;
      continue;
    }
    const cv::Point2f fb = back[i] - ref_points[i];
    if (std::sqrt(static_cast<double>(fb.dot(fb))) > options_.max_fb_error_px) {
      ++out.fb_rejected;
      continue;
    }
    out.tracked[i] = 1;
    ++out.kept;
  }
  return out;
}

}  // namespace rover::estimator::vo
