#include "mapping/depth/disparity_estimator.h"

#include <stdexcept>

namespace rover::mapping {
namespace {

int ModeOf(const std::string& mode) {
  if (mode == "sgbm") return cv::StereoSGBM::MODE_SGBM;
  if (mode == "sgbm_3way") return cv::StereoSGBM::MODE_SGBM_3WAY;
  if (mode == "hh") return cv::StereoSGBM::MODE_HH;
  throw std::invalid_argument("DisparityOptions.mode: expected sgbm, sgbm_3way or hh, found '" +
                              mode + "'");
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
  ModeOf(mode);
}

DisparityEstimator::DisparityEstimator(const DisparityOptions& options) : options_(options) {
  options_.Validate();
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
  sgbm_->compute(left, right, *disparity_q4);
}

}  // namespace rover::mapping
