#ifndef ROVER_MAPPING_DEPTH_DISPARITY_ESTIMATOR_H_
#define ROVER_MAPPING_DEPTH_DISPARITY_ESTIMATOR_H_

// Dense disparity from a rectified stereo pair with OpenCV's semi-global
// block matching (the thesis ran SGM on an FPGA at 1024x508 and 14.6 Hz;
// mapd runs StereoSGBM on a CPU core). The output is OpenCV's fixed point:
// CV_16S, 16 per pixel of disparity, with (min_disparity - 1) * 16 marking
// pixels without a match; DepthImage turns it into points.

#include <string>

#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

#include "core/config/config.h"

namespace rover::mapping {

struct DisparityOptions {
  int min_disparity_px = 0;
  /// Search range; a positive multiple of 16. 64 px at f = 460 px, b = 0.11 m
  /// reaches down to 0.8 m.
  int num_disparities_px = 64;
  int block_size_px = 5;  ///< odd, 1..11
  /// Smoothness penalties; 0 means OpenCV's usual 8 and 32 * block_size^2.
  int p1 = 0;
  int p2 = 0;
  /// 15 rather than OpenCV's usual 10: on the simulator's low-contrast
  /// patches at 3-4 m the second-best match is often nearly as good, and
  /// the few wrong matches that pass at 10 make steps on level ground.
  int uniqueness_ratio_pct = 15;
  int speckle_window_px = 100;  ///< 0 disables speckle filtering
  int speckle_range_px = 2;
  int max_left_right_diff_px = 1;  ///< left-right consistency; -1 disables it
  /// "sgbm" (5 directions), "sgbm_3way" (faster), "hh4" (4 directions, two
  /// passes) or "hh" (8 directions, two passes).
  std::string mode = "sgbm_3way";
  /// Also match the pair turned upside down and keep the mean of the two
  /// disparities where they agree within `max_flip_diff_px` (else: none).
  /// The one-pass modes aggregate their paths from the top of the image
  /// down, and on a surface whose disparity grows down the image (the
  /// ground) that pulls every disparity towards the rows above: -0.08 px on
  /// the simulator's terrain, +0.3 % depth at 2 m and +0.7 % at 4 m. The
  /// flipped pass is pulled the other way by as much. Twice the SGBM time;
  /// the two-pass modes cost about three times and keep +0.03 px.
  bool flip_pass = true;
  double max_flip_diff_px = 1.0;
  /// Texture filter: pixels whose mean horizontal intensity gradient over a
  /// 7x7 window is below this (digital numbers per pixel, as the sensor
  /// counted them) get no disparity. SGBM's smoothness terms otherwise carry
  /// disparities into textureless regions (sky, deep shadow), where they are
  /// matched sensor noise: on the simulator's pairs the sky measures 0.4-0.9
  /// DN/px, in-range ground 1.5-4.5. Where the left image was brightened
  /// after capture (a flat-field correction, see DisparityEstimator), its
  /// noise was too, and the threshold scales with the gain. 0 disables the
  /// filter.
  double min_texture_dn = 1.0;

  /// Absent keys keep their defaults; unknown keys are the caller's to check.
  static DisparityOptions Load(const ConfigNode& node);
  /// Throws std::invalid_argument "DisparityOptions.<key>: expected ..., found ...".
  void Validate() const;
};

class DisparityEstimator {
 public:
  /// `left_gain`: the gain each pixel of the rectified left image was
  /// brightened by after capture (calib::StereoRectifier::FlatFieldGain(0),
  /// CV_32FC1 of the image size, every value > 0), or empty for none. It
  /// scales the texture threshold per pixel: a gain of 1.5 in the corners
  /// brightens the sky's noise from 0.7 to 1.05 DN/px, past a fixed
  /// threshold, and SGBM matches it. Throws std::invalid_argument for
  /// invalid options or gain.
  explicit DisparityEstimator(const DisparityOptions& options, const cv::Mat& left_gain = {});

  /// Disparity of the rectified mono8 pair (same size, and the size of the
  /// left gain if there is one). Throws std::invalid_argument naming what is
  /// wrong with the images.
  void Compute(const cv::Mat& left, const cv::Mat& right, cv::Mat* disparity_q4) const;

  const DisparityOptions& options() const { return options_; }
  /// The fixed-point value OpenCV writes for "no match".
  int InvalidValue() const { return (options_.min_disparity_px - 1) * 16; }

 private:
  DisparityOptions options_;
  /// Mean of `a` and the second pass `b` where both matched and agree.
  void MergeFlipPass(const cv::Mat& b, cv::Mat* a) const;

  cv::Ptr<cv::StereoSGBM> sgbm_;
  /// min_texture_dn times the left gain per pixel (CV_32FC1); empty when
  /// there is no gain and the scalar threshold applies everywhere.
  cv::Mat min_texture_;
};

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_DEPTH_DISPARITY_ESTIMATOR_H_
