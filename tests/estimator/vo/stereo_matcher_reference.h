#ifndef ROVER_TESTS_ESTIMATOR_VO_STEREO_MATCHER_REFERENCE_H_
#define ROVER_TESTS_ESTIMATOR_VO_STEREO_MATCHER_REFERENCE_H_

// The exhaustive stereo search StereoMatcher::Match used before it became
// coarse-to-fine: cv::matchTemplate (TM_CCOEFF_NORMED) over the whole
// disparity range and every row of the band, in both directions. Kept as an
// independent oracle for the tests (same points, same sub-pixel positions)
// and as the in-run reference of bench_stereo_matcher, since the shared
// machines make absolute times drift.

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <vector>

#include "estimator/vo/stereo_matcher.h"

namespace rover::estimator::vo::testing {

inline std::vector<StereoPoint> ReferenceStereoMatch(const StereoMatcher& matcher,
                                                     const cv::Mat& left, const cv::Mat& right,
                                                     const std::vector<cv::Point2f>& left_points,
                                                     StereoMatchStats* stats = nullptr) {
  const StereoMatcherOptions& o = matcher.options();
  StereoMatchStats s;
  std::vector<StereoPoint> out;
  s.candidates = static_cast<int>(left_points.size());
  if (left.empty() || right.empty() || left.size() != right.size() || left.type() != CV_8UC1 ||
      right.type() != CV_8UC1 || left_points.empty()) {
    if (stats != nullptr) *stats = s;
    return out;
  }
  const int half = std::max(o.search_window_px, 3) / 2;
  const int side = 2 * half + 1;
  const int margin = std::max(o.search_row_margin_px, 0);
  const int d_max = static_cast<int>(std::ceil(o.max_disparity_px));
  const int d_min = std::max(static_cast<int>(std::floor(o.min_disparity_px)), 0);
  const cv::Rect image_rect(0, 0, left.cols, left.rows);
  cv::Mat score;
  const auto search = [&](const cv::Mat& from, const cv::Mat& to, int u, int v, int x_lo, int x_hi,
                          cv::Point2f* best_at) {
    const cv::Rect patch(u - half, v - half, side, side);
    if ((patch & image_rect) != patch) return false;
    const cv::Mat templ = from(patch);
    cv::Scalar mean, stddev;
    cv::meanStdDev(templ, mean, stddev);
    if (stddev[0] < o.min_template_stddev) return false;
    const cv::Rect strip =
        cv::Rect(x_lo - half, v - half - margin, x_hi - x_lo + side, side + 2 * margin) &
        image_rect;
    if (strip.width < side || strip.height < side) return false;
    cv::matchTemplate(to(strip), templ, score, cv::TM_CCOEFF_NORMED);
    double best = 0.0;
    cv::Point at;
    cv::minMaxLoc(score, nullptr, &best, nullptr, &at);
    if (!(best >= o.min_ncc)) return false;
    const auto offset = [](float a, float c, float b) {
      const float den = a - 2.0f * c + b;
      return den < 0.0f ? std::clamp(0.5f * (a - b) / den, -0.5f, 0.5f) : 0.0f;
    };
    float dx = 0.0f, dy = 0.0f;
    if (at.x > 0 && at.x + 1 < score.cols) {
      dx = offset(score.at<float>(at.y, at.x - 1), score.at<float>(at.y, at.x),
                  score.at<float>(at.y, at.x + 1));
    }
    if (at.y > 0 && at.y + 1 < score.rows) {
      dy = offset(score.at<float>(at.y - 1, at.x), score.at<float>(at.y, at.x),
                  score.at<float>(at.y + 1, at.x));
    }
    *best_at = cv::Point2f(static_cast<float>(strip.x + at.x + half) + dx,
                           static_cast<float>(strip.y + at.y + half) + dy);
    return true;
  };

  for (size_t i = 0; i < left_points.size(); ++i) {
    const cv::Point2f& l = left_points[i];
    const int u = static_cast<int>(std::lround(l.x));
    const int v = static_cast<int>(std::lround(l.y));
    cv::Point2f r;
    if (!search(left, right, u, v, u - d_max, u - d_min, &r)) {
      ++s.search_rejected;
      continue;
    }
    r += cv::Point2f(l.x - static_cast<float>(u), l.y - static_cast<float>(v));
    const int ur = static_cast<int>(std::lround(r.x));
    const int vr = static_cast<int>(std::lround(r.y));
    cv::Point2f back;
    if (!search(right, left, ur, vr, ur + d_min, ur + d_max, &back)) {
      ++s.consistency_rejected;
      continue;
    }
    back += cv::Point2f(r.x - static_cast<float>(ur), r.y - static_cast<float>(vr));
    const cv::Point2f fb = back - l;
    if (std::sqrt(static_cast<double>(fb.dot(fb))) > o.max_fb_error_px) {
      ++s.consistency_rejected;
      continue;
    }
    if (std::abs(static_cast<double>(l.y - r.y)) > o.max_row_error_px) {
      ++s.row_rejected;
      continue;
    }
    const double d = static_cast<double>(l.x - r.x);
    if (d < o.min_disparity_px) {
      ++s.disparity_rejected;
      continue;
    }
    const Eigen::Vector3d p = matcher.Triangulate(l, r);
    const double sigma = matcher.DepthSigma(p.z());
    if (sigma > o.max_depth_sigma_m || sigma > o.max_relative_depth_sigma * p.z()) {
      ++s.depth_sigma_rejected;
      continue;
    }
    StereoPoint sp;
    sp.feature_index = static_cast<int>(i);
    sp.left = l;
    sp.right = r;
    sp.p_cam0rect = p;
    sp.depth_sigma_m = sigma;
    out.push_back(sp);
  }
  s.accepted = static_cast<int>(out.size());
  if (stats != nullptr) *stats = s;
  return out;
}

}  // namespace rover::estimator::vo::testing

#endif  // ROVER_TESTS_ESTIMATOR_VO_STEREO_MATCHER_REFERENCE_H_
