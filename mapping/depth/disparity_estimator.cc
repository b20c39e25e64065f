#include "mapping/depth/disparity_estimator.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <stdexcept>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace rover::mapping {
namespace {

int ModeOf(const std::string& mode) {
  if (mode == "sgbm") return cv::StereoSGBM::MODE_SGBM;
  if (mode == "sgbm_3way") return cv::StereoSGBM::MODE_SGBM_3WAY;
  if (mode == "hh") return cv::StereoSGBM::MODE_HH;
  if (mode == "hh4") return cv::StereoSGBM::MODE_HH4;
  throw std::invalid_argument(
      "DisparityOptions.mode: expected sgbm, sgbm_3way, hh4 or hh, found '" + mode + "'");
}

}  // namespace

DisparityOptions DisparityOptions::Load(const ConfigNode& node) {
  DisparityOptions o;
  o.min_disparity_px = node.Get<int>("min_disparity_px", o.min_disparity_px);
  o.num_disparities_px = node.Get<int>("num_disparities_px", o.num_disparities_px);
  o.block_size_px = node.Get<int>("block_size_px", o.block_size_px);
  o.p1 = node.Get<int>("p1", o.p1);
  o.p2 = node.Get<int>("p2", o.p2);
  o.uniqueness_ratio_pct = node.Get<int>("uniqueness_ratio_pct", o.uniqueness_ratio_pct);
  o.speckle_window_px = node.Get<int>("speckle_window_px", o.speckle_window_px);
  o.speckle_range_px = node.Get<int>("speckle_range_px", o.speckle_range_px);
  o.max_left_right_diff_px = node.Get<int>("max_left_right_diff_px", o.max_left_right_diff_px);
  o.mode = node.Get<std::string>("mode", o.mode);
  o.min_texture_dn = node.Get<double>("min_texture_dn", o.min_texture_dn);
  o.flip_pass = node.Get<bool>("flip_pass", o.flip_pass);
  o.max_flip_diff_px = node.Get<double>("max_flip_diff_px", o.max_flip_diff_px);
  o.Validate();
  return o;
}

void DisparityOptions::Validate() const {
  const auto fail = [](const std::string& key, const std::string& expected, int found) {
    throw std::invalid_argument("DisparityOptions." + key + ": expected " + expected + ", found " +
                                std::to_string(found));
  };
  if (num_disparities_px <= 0 || num_disparities_px % 16 != 0) {
    fail("num_disparities_px", "a positive multiple of 16", num_disparities_px);
  }
  if (block_size_px < 1 || block_size_px > 11 || block_size_px % 2 == 0) {
    fail("block_size_px", "an odd number in 1..11", block_size_px);
  }
  if (p1 < 0) fail("p1", ">= 0", p1);
  if (p2 != 0 && p2 <= p1) fail("p2", "0 or more than p1", p2);
  if (uniqueness_ratio_pct < 0 || uniqueness_ratio_pct > 100) {
    fail("uniqueness_ratio_pct", "0..100", uniqueness_ratio_pct);
  }
  if (speckle_window_px < 0) fail("speckle_window_px", ">= 0", speckle_window_px);
  if (speckle_range_px < 0) fail("speckle_range_px", ">= 0", speckle_range_px);
  if (!(min_texture_dn >= 0.0) || !std::isfinite(min_texture_dn)) {
    throw std::invalid_argument("DisparityOptions.min_texture_dn: expected >= 0, found " +
                                std::to_string(min_texture_dn));
  }
  if (!(max_flip_diff_px >= 0.0) || !std::isfinite(max_flip_diff_px)) {
    throw std::invalid_argument("DisparityOptions.max_flip_diff_px: expected >= 0, found " +
                                std::to_string(max_flip_diff_px));
  }
  ModeOf(mode);
}

DisparityEstimator::DisparityEstimator(const DisparityOptions& options, const cv::Mat& left_gain)
    : options_(options) {
  options_.Validate();
  if (!left_gain.empty()) {
    double min_gain = 0.0;
    if (left_gain.type() != CV_32FC1) {
      throw std::invalid_argument(
          "DisparityEstimator: expected the left gain as CV_32FC1, found OpenCV type " +
          std::to_string(left_gain.type()));
    }
    cv::minMaxLoc(left_gain, &min_gain);
    if (!(min_gain > 0.0)) {
      throw std::invalid_argument(
          "DisparityEstimator: expected a left gain > 0 everywhere, found " +
          std::to_string(min_gain));
    }
    min_texture_ = left_gain * options_.min_texture_dn;
  }
  const int area = options_.block_size_px * options_.block_size_px;
  sgbm_ = cv::StereoSGBM::create(
      options_.min_disparity_px, options_.num_disparities_px, options_.block_size_px,
      options_.p1 > 0 ? options_.p1 : 8 * area, options_.p2 > 0 ? options_.p2 : 32 * area,
      options_.max_left_right_diff_px, 0, options_.uniqueness_ratio_pct, options_.speckle_window_px,
      options_.speckle_range_px, ModeOf(options_.mode));
}

void DisparityEstimator::Compute(const cv::Mat& left, const cv::Mat& right,
                                 cv::Mat* disparity_q4) const {
  if (left.empty() || right.empty() || left.type() != CV_8UC1 || right.type() != CV_8UC1) {
    throw std::invalid_argument("DisparityEstimator: expected two non-empty mono8 images");
  }
  if (left.size() != right.size()) {
    throw std::invalid_argument("DisparityEstimator: expected images of one size, found " +
                                std::to_string(left.cols) + "x" + std::to_string(left.rows) +
                                " and " + std::to_string(right.cols) + "x" +
                                std::to_string(right.rows));
  }
  if (!min_texture_.empty() && left.size() != min_texture_.size()) {
    throw std::invalid_argument("DisparityEstimator: expected images of the left gain's size " +
                                std::to_string(min_texture_.cols) + "x" +
                                std::to_string(min_texture_.rows) + ", found " +
                                std::to_string(left.cols) + "x" + std::to_string(left.rows));
  }
  sgbm_->compute(left, right, *disparity_q4);
  if (options_.flip_pass) {
    cv::Mat left_flipped, right_flipped, flipped_q4, second_q4;
    cv::flip(left, left_flipped, 0);
    cv::flip(right, right_flipped, 0);
    sgbm_->compute(left_flipped, right_flipped, flipped_q4);
    cv::flip(flipped_q4, second_q4, 0);
    MergeFlipPass(second_q4, disparity_q4);
  }
  // The matching window runs off the image within half a block of its
  // border: SGBM's values there (zero disparity, often) mean nothing, and
  // must not read as "infinitely far".
  const int margin = options_.block_size_px / 2 + 1;
  const cv::Scalar invalid(InvalidValue());
  disparity_q4->rowRange(0, std::min(margin, disparity_q4->rows)).setTo(invalid);
  disparity_q4->rowRange(std::max(0, disparity_q4->rows - margin), disparity_q4->rows)
      .setTo(invalid);
  disparity_q4->colRange(0, std::min(margin, disparity_q4->cols)).setTo(invalid);
  disparity_q4->colRange(std::max(0, disparity_q4->cols - margin), disparity_q4->cols)
      .setTo(invalid);
  if (options_.min_texture_dn > 0.0) {
    // Mean |dI/dx| (Sobel normalised to one pixel step) over 7x7.
    cv::Mat gradient;
    cv::Sobel(left, gradient, CV_32F, 1, 0, 3, 1.0 / 8.0);
    cv::Mat texture;
    cv::boxFilter(cv::abs(gradient), texture, CV_32F, cv::Size(7, 7));
    // In sensor counts: a brightened pixel's noise was brightened too.
    if (min_texture_.empty()) {
      disparity_q4->setTo(cv::Scalar(InvalidValue()),
                          texture < static_cast<float>(options_.min_texture_dn));
    } else {
      disparity_q4->setTo(cv::Scalar(InvalidValue()), texture < min_texture_);
    }
  }
}

void DisparityEstimator::MergeFlipPass(const cv::Mat& b, cv::Mat* a) const {
  const int invalid = InvalidValue();
  const int min_valid = options_.min_disparity_px * 16;
  const auto max_diff_q4 = static_cast<int>(std::lround(options_.max_flip_diff_px * 16.0));
  for (int v = 0; v < a->rows; ++v) {
    int16_t* row_a = a->ptr<int16_t>(v);
    const int16_t* row_b = b.ptr<int16_t>(v);
    for (int u = 0; u < a->cols; ++u) {
      const int da = row_a[u];
      const int db = row_b[u];
      if (da < min_valid || db < min_valid || std::abs(da - db) > max_diff_q4) {
        row_a[u] = static_cast<int16_t>(invalid);
        continue;
      }
      // Half of an odd sum rounds up on every other pixel: no bias from
      // the fixed point.
      row_a[u] = static_cast<int16_t>((da + db + ((u + v) & 1)) >> 1);
    }
  }
}

}  // namespace rover::mapping
