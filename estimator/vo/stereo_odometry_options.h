#ifndef ROVER_ESTIMATOR_VO_STEREO_ODOMETRY_OPTIONS_H_
#define ROVER_ESTIMATOR_VO_STEREO_ODOMETRY_OPTIONS_H_

// Options of the stereo VO (StereoOdometry) and its stages, loadable from a
// YAML map. Every key is optional; absent keys keep the defaults below.

#include <string>

#include "core/calib/stereo_rectifier.h"
#include "core/config/config.h"
#include "estimator/vo/feature_detector.h"
#include "estimator/vo/motion_estimator.h"
#include "estimator/vo/stereo_matcher.h"
#include "estimator/vo/temporal_tracker.h"

namespace rover::estimator::vo {

/// Keyframe policy.
struct KeyframeOptions {
  int max_keyframes = 5;  ///< history kept (thesis: n = 5)
  /// A new keyframe when fewer tracked inliers remain than this ...
  int min_tracked_inliers = 60;
  /// ... or than this fraction of the keyframe's points.
  double min_tracked_fraction = 0.4;
  double max_translation_m = 0.5;  ///< or the camera moved further than this
  double max_rotation_rad = 0.26;  ///< or turned more than this (15 deg)
  /// A keyframe needs at least this many triangulated points.
  int min_keyframe_points = 30;
  /// An older keyframe replaces the active one only with at least this many
  /// inliers and more than the active keyframe has.
  int min_revisit_inliers = 80;

  static KeyframeOptions Load(const ConfigNode& node);
  void Validate() const;
};

/// Input checks on each image.
struct ImageCheckOptions {
  double min_mean_dn = 10.0;   ///< darker: black frame
  double max_mean_dn = 240.0;  ///< brighter: over-exposed frame
  double min_stddev_dn = 4.0;  ///< flatter: textureless frame
  /// Capture gaps longer than this many nominal frame periods count the
  /// missing frames as dropped (needs nominal_rate_hz > 0).
  double drop_gap_periods = 1.5;
  double nominal_rate_hz = 0.0;  ///< 0: unknown, drops not counted

  static ImageCheckOptions Load(const ConfigNode& node);
  void Validate() const;
};

struct StereoOdometryOptions {
  calib::StereoRectifierOptions rectifier;
  /// Features at least a KLT window apart, so that no two tracks share
  /// pixels and their errors stay independent, as the covariance assumes.
  FeatureDetectorOptions detector{.cell_size_px = 40, .max_per_cell = 2, .min_distance_px = 22.0};
  StereoMatcherOptions stereo;
  TemporalTrackerOptions tracker;
  /// Covariance scale calibrated on simulated drives (a mean NEES of 5.6-6.3
  /// for 6 dof on four rendered drives, images flat-fielded, 11 px tracking
  /// window), see estimator/vo/README.md.
  MotionEstimatorOptions motion{.covariance_scale = 0.70};
  KeyframeOptions keyframes;
  ImageCheckOptions checks;
  /// Features kept per keyframe (strongest first after bucketing).
  int max_features = 400;
  /// Stereo KLT of tracked features: window and pyramid levels.
  int stereo_klt_window_px = 15;
  int stereo_klt_levels = 2;

  /// Keys (all optional): the maps rectifier, detector, stereo, tracker,
  /// motion, keyframes, checks, and max_features, stereo_klt_window_px,
  /// stereo_klt_levels. Ranges are checked; unknown keys are errors.
  static StereoOdometryOptions Load(const ConfigNode& node);
  /// Load() of a whole YAML file, rejecting unknown keys anywhere.
  static StereoOdometryOptions LoadFile(const std::string& path);
  /// Throws std::invalid_argument naming the first bad value.
  void Validate() const;
};

}  // namespace rover::estimator::vo

#endif  // ROVER_ESTIMATOR_VO_STEREO_ODOMETRY_OPTIONS_H_
