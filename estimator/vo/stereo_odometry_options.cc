#include "estimator/vo/stereo_odometry_options.h"

#include <stdexcept>

namespace rover::estimator::vo {
namespace {

template <typename Options, typename Loader>
Options LoadSection(const ConfigNode& parent, const char* key, Loader load) {
  Options o;
  if (parent.Has(key)) load(parent.Child(key), &o);
  return o;
}

void LoadRectifier(const ConfigNode& n, calib::StereoRectifierOptions* o) {
  o->alpha = n.GetInRange<double>("alpha", 0.0, 1.0, o->alpha);
}

void LoadDetector(const ConfigNode& n, FeatureDetectorOptions* o) {
  o->cell_size_px = n.GetInRange<int>("cell_size_px", 8, 512, o->cell_size_px);
  o->max_per_cell = n.GetInRange<int>("max_per_cell", 1, 100, o->max_per_cell);
  o->fast_threshold = n.GetInRange<int>("fast_threshold", 1, 255, o->fast_threshold);
  o->min_fast_threshold = n.GetInRange<int>("min_fast_threshold", 1, 255, o->min_fast_threshold);
  o->border_px = n.GetInRange<int>("border_px", 0, 100, o->border_px);
  o->min_distance_px = n.GetInRange<double>("min_distance_px", 0.0, 100.0, o->min_distance_px);
}

void LoadStereo(const ConfigNode& n, StereoMatcherOptions* o) {
  o->search_window_px = n.GetInRange<int>("search_window_px", 3, 31, o->search_window_px);
  o->search_row_margin_px =
      n.GetInRange<int>("search_row_margin_px", 0, 5, o->search_row_margin_px);
  o->max_disparity_px = n.GetInRange<double>("max_disparity_px", 2.0, 512.0, o->max_disparity_px);
  o->min_ncc = n.GetInRange<double>("min_ncc", 0.0, 1.0, o->min_ncc);
  o->min_template_stddev =
      n.GetInRange<double>("min_template_stddev", 0.0, 100.0, o->min_template_stddev);
  o->max_row_error_px = n.GetInRange<double>("max_row_error_px", 0.0, 5.0, o->max_row_error_px);
  o->max_fb_error_px = n.GetInRange<double>("max_fb_error_px", 0.0, 5.0, o->max_fb_error_px);
  o->min_disparity_px = n.GetInRange<double>("min_disparity_px", 0.0, 100.0, o->min_disparity_px);
  o->disparity_sigma_px =
      n.GetInRange<double>("disparity_sigma_px", 0.01, 10.0, o->disparity_sigma_px);
  o->max_depth_sigma_m =
      n.GetInRange<double>("max_depth_sigma_m", 0.001, 100.0, o->max_depth_sigma_m);
  o->max_relative_depth_sigma =
      n.GetInRange<double>("max_relative_depth_sigma", 0.001, 10.0, o->max_relative_depth_sigma);
}

void LoadTracker(const ConfigNode& n, TemporalTrackerOptions* o) {
  o->window_px = n.GetInRange<int>("window_px", 5, 63, o->window_px);
  o->pyramid_levels = n.GetInRange<int>("pyramid_levels", 0, 6, o->pyramid_levels);
  o->max_iterations = n.GetInRange<int>("max_iterations", 1, 200, o->max_iterations);
  o->max_fb_error_px = n.GetInRange<double>("max_fb_error_px", 0.01, 10.0, o->max_fb_error_px);
  o->border_px = n.GetInRange<int>("border_px", 0, 100, o->border_px);
}

void LoadMotion(const ConfigNode& n, MotionEstimatorOptions* o) {
  o->ransac_max_iterations =
      n.GetInRange<int>("ransac_max_iterations", 1, 100000, o->ransac_max_iterations);
  o->ransac_confidence =
      n.GetInRange<double>("ransac_confidence", 0.5, 0.999999, o->ransac_confidence);
  o->inlier_threshold_px =
      n.GetInRange<double>("inlier_threshold_px", 0.1, 50.0, o->inlier_threshold_px);
  o->seed = n.Get<uint64_t>("seed", o->seed);
  o->min_inliers = n.GetInRange<int>("min_inliers", 4, 10000, o->min_inliers);
  o->lm_max_iterations = n.GetInRange<int>("lm_max_iterations", 1, 1000, o->lm_max_iterations);
  o->pixel_sigma_px = n.GetInRange<double>("pixel_sigma_px", 0.01, 10.0, o->pixel_sigma_px);
  o->covariance_scale = n.GetInRange<double>("covariance_scale", 0.01, 100.0, o->covariance_scale);
  o->good_inliers = n.GetInRange<int>("good_inliers", 1, 10000, o->good_inliers);
  o->good_spread = n.GetInRange<double>("good_spread", 0.0, 1.0, o->good_spread);
  o->spread_grid = n.GetInRange<int>("spread_grid", 1, 32, o->spread_grid);
}

}  // namespace

KeyframeOptions KeyframeOptions::Load(const ConfigNode& n) {
  KeyframeOptions o;
  o.max_keyframes = n.GetInRange<int>("max_keyframes", 1, 5, o.max_keyframes);
  o.min_tracked_inliers = n.GetInRange<int>("min_tracked_inliers", 4, 10000, o.min_tracked_inliers);
  o.min_tracked_fraction =
      n.GetInRange<double>("min_tracked_fraction", 0.0, 1.0, o.min_tracked_fraction);
  o.max_translation_m = n.GetInRange<double>("max_translation_m", 0.01, 100.0, o.max_translation_m);
  o.max_rotation_rad = n.GetInRange<double>("max_rotation_rad", 0.001, 3.0, o.max_rotation_rad);
  o.min_keyframe_points = n.GetInRange<int>("min_keyframe_points", 4, 10000, o.min_keyframe_points);
  o.min_revisit_inliers = n.GetInRange<int>("min_revisit_inliers", 4, 10000, o.min_revisit_inliers);
  return o;
}

void KeyframeOptions::Validate() const {
  // At most 5: the filter holds 8 clones, and frames in flight need the rest.
  if (max_keyframes < 1 || max_keyframes > 5) {
    throw std::invalid_argument("keyframes.max_keyframes: expected 1..5, found " +
                                std::to_string(max_keyframes));
  }
  if (min_tracked_inliers < 4 || min_keyframe_points < 4 || min_revisit_inliers < 4) {
    throw std::invalid_argument(
        "keyframes: min_tracked_inliers, min_keyframe_points and min_revisit_inliers must be "
        ">= 4 (a pose needs at least 4 points)");
  }
  if (!(min_tracked_fraction >= 0.0 && min_tracked_fraction <= 1.0)) {
    throw std::invalid_argument("keyframes.min_tracked_fraction: expected [0, 1]");
  }
  if (!(max_translation_m > 0.0) || !(max_rotation_rad > 0.0)) {
    throw std::invalid_argument(
        "keyframes.max_translation_m and max_rotation_rad: expected positive values");
  }
}

ImageCheckOptions ImageCheckOptions::Load(const ConfigNode& n) {
  ImageCheckOptions o;
  o.min_mean_dn = n.GetInRange<double>("min_mean_dn", 0.0, 255.0, o.min_mean_dn);
  o.max_mean_dn = n.GetInRange<double>("max_mean_dn", 0.0, 255.0, o.max_mean_dn);
  o.min_stddev_dn = n.GetInRange<double>("min_stddev_dn", 0.0, 128.0, o.min_stddev_dn);
  o.drop_gap_periods = n.GetInRange<double>("drop_gap_periods", 1.01, 100.0, o.drop_gap_periods);
  o.nominal_rate_hz = n.GetInRange<double>("nominal_rate_hz", 0.0, 1000.0, o.nominal_rate_hz);
  return o;
}

void ImageCheckOptions::Validate() const {
  if (!(min_mean_dn < max_mean_dn)) {
    throw std::invalid_argument("checks: expected min_mean_dn < max_mean_dn, found " +
                                std::to_string(min_mean_dn) + " >= " + std::to_string(max_mean_dn));
  }
  if (!(drop_gap_periods > 1.0) || !(nominal_rate_hz >= 0.0)) {
    throw std::invalid_argument("checks: expected drop_gap_periods > 1 and nominal_rate_hz >= 0");
  }
}

StereoOdometryOptions StereoOdometryOptions::Load(const ConfigNode& n) {
  StereoOdometryOptions o;
  o.rectifier = LoadSection<calib::StereoRectifierOptions>(n, "rectifier", LoadRectifier);
  o.detector = LoadSection<FeatureDetectorOptions>(n, "detector", LoadDetector);
  o.stereo = LoadSection<StereoMatcherOptions>(n, "stereo", LoadStereo);
  o.tracker = LoadSection<TemporalTrackerOptions>(n, "tracker", LoadTracker);
  o.motion = LoadSection<MotionEstimatorOptions>(n, "motion", LoadMotion);
  if (n.Has("keyframes")) o.keyframes = KeyframeOptions::Load(n.Child("keyframes"));
  if (n.Has("checks")) o.checks = ImageCheckOptions::Load(n.Child("checks"));
  o.max_features = n.GetInRange<int>("max_features", 10, 5000, o.max_features);
  o.stereo_klt_window_px = n.GetInRange<int>("stereo_klt_window_px", 5, 63, o.stereo_klt_window_px);
  o.stereo_klt_levels = n.GetInRange<int>("stereo_klt_levels", 0, 5, o.stereo_klt_levels);
  o.Validate();
  return o;
}

StereoOdometryOptions StereoOdometryOptions::LoadFile(const std::string& path) {
  const ConfigNode root = ConfigNode::LoadFile(path);
  StereoOdometryOptions o = Load(root);
  root.CheckNoUnknownKeysRecursive();
  return o;
}

void StereoOdometryOptions::Validate() const {
  keyframes.Validate();
  checks.Validate();
  if (detector.min_fast_threshold > detector.fast_threshold) {
    throw std::invalid_argument("detector: expected min_fast_threshold <= fast_threshold");
  }
  if (stereo.search_window_px % 2 == 0) {
    throw std::invalid_argument("stereo.search_window_px: expected an odd size, found " +
                                std::to_string(stereo.search_window_px));
  }
  if (motion.min_inliers > keyframes.min_keyframe_points) {
    throw std::invalid_argument(
        "motion.min_inliers must not exceed keyframes.min_keyframe_points (a keyframe could "
        "never be tracked)");
  }
  if (max_features < keyframes.min_keyframe_points) {
    throw std::invalid_argument("max_features: expected >= keyframes.min_keyframe_points");
  }
}

}  // namespace rover::estimator::vo
