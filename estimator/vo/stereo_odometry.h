#ifndef ROVER_ESTIMATOR_VO_STEREO_ODOMETRY_H_
#define ROVER_ESTIMATOR_VO_STEREO_ODOMETRY_H_

// Keyframe stereo visual odometry (thesis 4.1.1): every stereo pair yields the
// relative pose keyframe -> current frame with its covariance, as the local
// reference filter's relative-pose update consumes it.
//
// Per frame:
//  1. input checks: capture order, dropped-frame gaps, image type and size,
//     exposure (black / over-exposed / textureless frames are refused);
//  2. rectification of both images (maps computed once);
//  3. pyramidal KLT of the active keyframe's features into the current left
//     image (initial guess: where they were in the previous frame), with a
//     forward-backward check;
//  4. stereo correspondences of the tracked features by KLT along the
//     rectified row, started at the keyframe's disparity, with a row check;
//  5. P3P RANSAC + Levenberg-Marquardt in both images, covariance from the
//     inverse Gauss-Newton Hessian, inflated for few or badly spread inliers;
//  6. keyframe decision: a new keyframe when too few features are still
//     tracked, or the motion since the keyframe exceeds the translation or
//     rotation limit. Before making one, the older keyframes of the history
//     (up to 5, as in the thesis) are tried: if one of them is seen better
//     than the active one (for example after turning back), it becomes the
//     active keyframe again, which keeps the estimate locally drift-free.
//     Otherwise the current frame becomes a keyframe: its tracked stereo
//     points are triangulated afresh and new FAST features are detected in
//     empty grid cells and matched by row search.
//
// Without a right image the frame is tracked against the keyframe's 3-D
// points in the left image only (a wider covariance) and cannot become a
// keyframe. When tracking fails, the current frame starts a new keyframe
// chain; the filter bridges the gap with IMU and wheels.
//
// Determinism: the output is a pure function of the sequence of frames and
// the options (fixed RANSAC seed, no threads, no clocks in the decisions).
// Stage timings are measured but never used in a decision.
//
// Not thread-safe: one instance per VO thread.

#include <array>
#include <chrono>
#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "core/calib/stereo_rectifier.h"
#include "core/time/time.h"
#include "estimator/eskf/eskf_input.h"
#include "estimator/vo/feature_detector.h"
#include "estimator/vo/motion_estimator.h"
#include "estimator/vo/stereo_matcher.h"
#include "estimator/vo/stereo_odometry_options.h"
#include "estimator/vo/temporal_tracker.h"

namespace rover::estimator::vo {

/// One stereo exposure as the camera thread hands it over: raw (distorted)
/// 8-bit grey images sharing one capture time. An empty cam1 means the right
/// image is missing.
struct StereoImages {
  Time capture;
  uint64_t sequence = 0;  ///< camera frame counter (informative)
  cv::Mat cam0;
  cv::Mat cam1;
};

/// What became of one frame.
enum class VoStatus : uint8_t {
  kTracked,        ///< a measurement from the active keyframe
  kNewKeyframe,    ///< a measurement, and the frame is now the active keyframe
  kRevisited,      ///< a measurement from an older keyframe, now active again
  kFirstKeyframe,  ///< the first keyframe (or a restart): no measurement
  kLeftOnly,       ///< a measurement from the left image only (no right image)
  kOutOfOrder,     ///< capture not after the previous frame: refused
  kBadImage,       ///< empty, wrong type or size: refused
  kBlackImage,     ///< too dark: refused
  kOverExposed,    ///< too bright: refused
  kTextureless,    ///< too flat, or too few features / stereo points: refused
  kTrackingLost,   ///< motion estimation failed: no measurement, new chain
  kNoRightImage,   ///< right image missing and no keyframe to track against
};
inline constexpr int kVoStatusCount = 12;
const char* VoStatusName(VoStatus status);

/// Wall time of each stage of the last frame [ms] (never used in decisions).
struct VoStageTimes {
  double check_ms = 0.0;
  double rectify_ms = 0.0;
  double pyramid_ms = 0.0;
  double track_ms = 0.0;   ///< temporal KLT (+ revisit tries)
  double stereo_ms = 0.0;  ///< stereo KLT of tracks + row search of new features
  double detect_ms = 0.0;
  double ransac_ms = 0.0;
  double refine_ms = 0.0;  ///< LM + covariance
  double total_ms = 0.0;
};

/// Quality figures of one frame.
struct VoQuality {
  int keyframe_points = 0;  ///< 3-D points of the keyframe used
  int tracked = 0;          ///< temporal tracks that passed the checks
  int with_right = 0;       ///< of those, with a right-image correspondence
  int inliers = 0;
  double rms_error_px = 0.0;
  double spread = 0.0;
  double inflation = 1.0;
  int ransac_iterations = 0;
  int new_features = 0;  ///< detected for a new keyframe
};

/// Result of one Process() call.
struct VoFrameResult {
  VoStatus status = VoStatus::kBadImage;
  /// Present for kTracked, kNewKeyframe, kRevisited, kLeftOnly. `stamp` (the
  /// delivery time) is set to the capture time; the caller sets the real one.
  std::optional<RelativePoseMeasurement> measurement;
  VoQuality quality;
  VoStageTimes times;
  /// VO-only pose of the body at this capture in the VO's odometry frame
  /// (the body at the first keyframe), chained through the keyframes; valid
  /// whenever the frame was tracked or started a chain.
  std::optional<Eigen::Isometry3d> T_odom_body;
};

/// Counters since construction.
struct VoHealth {
  uint64_t frames = 0;        ///< Process() calls
  uint64_t measurements = 0;  ///< relative poses emitted
  uint64_t keyframes = 0;     ///< including first keyframes and restarts
  uint64_t revisits = 0;
  uint64_t restarts = 0;        ///< chains restarted after a loss
  uint64_t dropped_frames = 0;  ///< missing frames inferred from capture gaps
  uint64_t missing_right = 0;
  uint64_t inflated = 0;  ///< measurements with an inflated covariance
  std::array<uint64_t, kVoStatusCount> by_status{};
  VoStatus last_status = VoStatus::kBadImage;
  /// False after a refused or lost frame, true again after a measurement.
  bool healthy = false;

  uint64_t Count(VoStatus status) const { return by_status[static_cast<int>(status)]; }
};

class StereoOdometry {
 public:
  /// Builds the rectifier and every stage. Returns nullopt with a reason in
  /// *error when the calibration is unusable. Throws std::invalid_argument
  /// for bad options.
  static std::optional<StereoOdometry> Create(const calib::CameraModel& cam0,
                                              const calib::CameraModel& cam1,
                                              const StereoOdometryOptions& options,
                                              std::string* error = nullptr);

  /// Processes one stereo exposure; never throws on bad images.
  VoFrameResult Process(const StereoImages& frame);

  /// Makes the next tracked frame that has a right image a keyframe, whatever
  /// the keyframe policy says. For when the consumer cannot use the current
  /// keyframes, e.g. a filter that started after they were captured and so
  /// holds no clone of them.
  void RequestKeyframe() { keyframe_requested_ = true; }

  const VoHealth& health() const { return health_; }
  const StereoOdometryOptions& options() const { return options_; }
  const calib::StereoRectifier& rectifier() const { return rectifier_; }
  /// Keyframes currently held (<= max_keyframes).
  int keyframe_count() const { return static_cast<int>(keyframes_.size()); }

 private:
  struct Keyframe {
    Time capture;
    std::vector<cv::Mat> pyramid;  ///< left rectified image pyramid
    std::vector<cv::Point2f> pixels;
    std::vector<float> disparity_px;
    std::vector<Eigen::Vector3d> points_cam0rect;
    std::vector<Eigen::Matrix3d> point_covariances;  ///< from the stereo error model [m^2]
    Eigen::Isometry3d T_odom_cam = Eigen::Isometry3d::Identity();
    /// Where each point was in the last frame tracked against this keyframe.
    std::vector<cv::Point2f> last_pixels;
  };
  struct Attempt;

  StereoOdometry(const calib::StereoRectifier& rectifier, const StereoOdometryOptions& options);

  int PyramidWindowPx() const;
  /// Order, drops, image type/size and exposure; kTracked when usable.
  VoStatus CheckImages(const StereoImages& frame, bool* has_right);
  VoStatus CheckExposure(const cv::Mat& image) const;
  /// Tracks the active keyframe into the current frame and decides on keyframes.
  VoStatus TrackFrame(Time capture, bool has_right, VoFrameResult* result);
  Attempt TrackAgainst(int keyframe, const std::optional<Eigen::Isometry3d>& T_cur_kf_guess,
                       bool has_right, VoFrameResult* result);
  /// Stereo KLT of current left points into the current right image;
  /// `right` holds the initial guesses on entry.
  void MatchRight(const std::vector<cv::Point2f>& left, std::vector<cv::Point2f>* right,
                  std::vector<unsigned char>* ok) const;
  bool NeedsKeyframe(const Attempt& attempt) const;
  std::optional<Attempt> TryRevisit(const Attempt& current, bool has_right, VoFrameResult* result);
  void RememberTracks(const Attempt& attempt, Keyframe* keyframe) const;
  Eigen::Matrix3d PointCovariance(const Eigen::Vector3d& p, double disparity_px) const;
  bool AddStereoPoint(const cv::Point2f& left, const cv::Point2f& right, Keyframe* kf) const;
  /// Makes the current frame a keyframe at T_odom_cam; false (nothing
  /// changed) when it has too few stereo points.
  bool MakeKeyframe(Time capture, const Attempt* attempt, const Eigen::Isometry3d& T_odom_cam,
                    VoFrameResult* result);
  void FillQuality(const Attempt& attempt, VoFrameResult* result) const;
  void Finish(VoStatus status, std::chrono::steady_clock::time_point start, VoFrameResult* result);

  calib::StereoRectifier rectifier_;
  StereoOdometryOptions options_;
  FeatureDetector detector_;
  StereoMatcher matcher_;
  TemporalTracker tracker_;
  MotionEstimator motion_;
  Eigen::Isometry3d T_body_cam0rect_;

  std::deque<Keyframe> keyframes_;
  int active_ = -1;  ///< index into keyframes_
  std::optional<Time> last_capture_;
  bool keyframe_requested_ = false;
  /// Camera pose of the last tracked frame in the odometry frame; a new chain
  /// after a loss starts here.
  Eigen::Isometry3d T_odom_cam_last_ = Eigen::Isometry3d::Identity();
  // Per-frame work buffers, reused to avoid reallocating every frame.
  cv::Mat rect0_, rect1_;
  std::vector<cv::Mat> pyramid0_, pyramid1_;
  VoHealth health_;
};

}  // namespace rover::estimator::vo

#endif  // ROVER_ESTIMATOR_VO_STEREO_ODOMETRY_H_
