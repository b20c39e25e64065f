#include "estimator/vo/stereo_odometry.h"

#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <utility>

namespace rover::estimator::vo {
namespace {

using Clock = std::chrono::steady_clock;

/// Milliseconds since `*since`, which moves to now (timings only, never decisions).
double Lap(Clock::time_point* since) {
  const Clock::time_point now = Clock::now();
  const double ms = std::chrono::duration<double, std::milli>(now - *since).count();
  *since = now;
  return ms;
}

double RotationAngleRad(const Eigen::Isometry3d& T) {
  return Eigen::AngleAxisd(T.linear()).angle();
}

}  // namespace

const char* VoStatusName(VoStatus status) {
  switch (status) {
    case VoStatus::kTracked:
      return "tracked";
    case VoStatus::kNewKeyframe:
      return "new_keyframe";
    case VoStatus::kRevisited:
      return "revisited";
    case VoStatus::kFirstKeyframe:
      return "first_keyframe";
    case VoStatus::kLeftOnly:
      return "left_only";
    case VoStatus::kOutOfOrder:
      return "out_of_order";
    case VoStatus::kBadImage:
      return "bad_image";
    case VoStatus::kBlackImage:
      return "black_image";
    case VoStatus::kOverExposed:
      return "over_exposed";
    case VoStatus::kTextureless:
      return "textureless";
    case VoStatus::kTrackingLost:
      return "tracking_lost";
    case VoStatus::kNoRightImage:
      return "no_right_image";
  }
  return "unknown";
}

/// One try of the current frame against one keyframe.
struct StereoOdometry::Attempt {
  int keyframe = -1;
  MotionEstimate motion;
  std::vector<StereoObservation> observations;
  std::vector<int> point_of_observation;  ///< observation -> keyframe point
  int tracked = 0;
  int with_right = 0;
};

std::optional<StereoOdometry> StereoOdometry::Create(const calib::CameraModel& cam0,
                                                     const calib::CameraModel& cam1,
                                                     const StereoOdometryOptions& options,
                                                     std::string* error) {
  options.Validate();
  std::optional<calib::StereoRectifier> rectifier =
      calib::StereoRectifier::Create(cam0, cam1, options.rectifier);
  if (!rectifier) {
    if (error != nullptr) {
      *error =
          "unusable stereo calibration: expected two cameras of the same non-zero size and "
          "distortion model, positive focal lengths and cam1 to the right of cam0";
    }
    return std::nullopt;
  }
  return StereoOdometry(*rectifier, options);
}

StereoOdometry::StereoOdometry(const calib::StereoRectifier& rectifier,
                               const StereoOdometryOptions& options)
    : rectifier_(rectifier),
      options_(options),
      detector_(options.detector),
      matcher_(rectifier.intrinsics(), rectifier.baseline_m(), options.stereo),
      tracker_(options.tracker),
      motion_(rectifier.intrinsics(), rectifier.baseline_m(), rectifier.image_size(),
              options.motion),
      T_body_cam0rect_(rectifier.T_body_cam0rect()),
      T_odom_cam_last_(rectifier.T_body_cam0rect()) {}

int StereoOdometry::PyramidWindowPx() const {
  return std::max(options_.tracker.window_px, options_.stereo_klt_window_px);
}

VoFrameResult StereoOdometry::Process(const StereoImages& frame) {
  Clock::time_point clock = Clock::now();
  const Clock::time_point start = clock;
  VoFrameResult result;
  ++health_.frames;
  bool has_right = false;
  const VoStatus check = CheckImages(frame, &has_right);
  result.times.check_ms = Lap(&clock);
  if (check != VoStatus::kTracked) {
    Finish(check, start, &result);
    return result;
  }
  if (active_ < 0 && !has_right) {
    Finish(VoStatus::kNoRightImage, start, &result);
    return result;
  }
  rectifier_.RectifyOne(0, frame.cam0, &rect0_);
  if (has_right) rectifier_.RectifyOne(1, frame.cam1, &rect1_);
  result.times.rectify_ms = Lap(&clock);
  const int window = PyramidWindowPx();
  TemporalTracker::BuildPyramid(
      rect0_, window, std::max(options_.tracker.pyramid_levels, options_.stereo_klt_levels),
      &pyramid0_);
  if (has_right) {
    TemporalTracker::BuildPyramid(rect1_, window, options_.stereo_klt_levels, &pyramid1_);
  }
  result.times.pyramid_ms = Lap(&clock);

  if (active_ < 0) {
    const bool started = MakeKeyframe(frame.capture, nullptr, T_odom_cam_last_, &result);
    if (started) result.T_odom_body = T_odom_cam_last_ * rectifier_.T_cam0rect_body();
    Finish(started ? VoStatus::kFirstKeyframe : VoStatus::kTextureless, start, &result);
    return result;
  }
  Finish(TrackFrame(frame.capture, has_right, &result), start, &result);
  return result;
}

VoStatus StereoOdometry::TrackFrame(Time capture, bool has_right, VoFrameResult* result) {
  Attempt attempt = TrackAgainst(active_, std::nullopt, has_right, result);
  if (!attempt.motion.valid) {
    // A new chain from this frame; the filter bridges the gap with IMU and wheels.
    ++health_.restarts;
    keyframes_.clear();
    active_ = -1;
    if (has_right && MakeKeyframe(capture, nullptr, T_odom_cam_last_, result)) {
      result->T_odom_body = T_odom_cam_last_ * rectifier_.T_cam0rect_body();
    }
    return VoStatus::kTrackingLost;
  }
  bool need_keyframe = keyframe_requested_ || NeedsKeyframe(attempt);
  VoStatus status = has_right ? VoStatus::kTracked : VoStatus::kLeftOnly;
  if (need_keyframe && !keyframe_requested_ && keyframes_.size() > 1) {
    std::optional<Attempt> revisit = TryRevisit(attempt, has_right, result);
    if (revisit) {
      attempt = std::move(*revisit);
      active_ = attempt.keyframe;
      need_keyframe = false;
      status = VoStatus::kRevisited;
      ++health_.revisits;
    }
  }
  Keyframe& keyframe = keyframes_[static_cast<size_t>(attempt.keyframe)];
  RememberTracks(attempt, &keyframe);
  const Eigen::Isometry3d T_odom_cam = keyframe.T_odom_cam * attempt.motion.T_cur_ref.inverse();
  RelativePoseMeasurement m =
      ToBodyRelativePose(attempt.motion.T_cur_ref, attempt.motion.covariance, T_body_cam0rect_);
  m.stamp = capture;
  m.from_stamp = keyframe.capture;
  m.to_stamp = capture;
  if (need_keyframe && has_right && MakeKeyframe(capture, &attempt, T_odom_cam, result)) {
    m.to_is_keyframe = true;
    status = VoStatus::kNewKeyframe;
    keyframe_requested_ = false;
  }
  m.oldest_keyframe_stamp = keyframes_.front().capture;
  T_odom_cam_last_ = T_odom_cam;
  result->T_odom_body = T_odom_cam * rectifier_.T_cam0rect_body();
  result->measurement = m;
  FillQuality(attempt, result);
  return status;
}

VoStatus StereoOdometry::CheckImages(const StereoImages& frame, bool* has_right) {
  *has_right = false;
  if (last_capture_ && frame.capture <= *last_capture_) return VoStatus::kOutOfOrder;
  const ImageCheckOptions& c = options_.checks;
  if (last_capture_ && c.nominal_rate_hz > 0.0) {
    const double gap_periods = (frame.capture - *last_capture_).ToSeconds() * c.nominal_rate_hz;
    if (gap_periods > c.drop_gap_periods) {
      health_.dropped_frames += static_cast<uint64_t>(std::llround(gap_periods) - 1);
    }
  }
  last_capture_ = frame.capture;
  const cv::Size size = rectifier_.image_size();
  const auto usable = [&](const cv::Mat& m) {
    return !m.empty() && m.type() == CV_8UC1 && m.size() == size;
  };
  if (!usable(frame.cam0)) return VoStatus::kBadImage;
  const VoStatus left = CheckExposure(frame.cam0);
  if (left != VoStatus::kTracked) return left;
  *has_right = usable(frame.cam1) && CheckExposure(frame.cam1) == VoStatus::kTracked;
  if (!*has_right) ++health_.missing_right;
  return VoStatus::kTracked;
}

VoStatus StereoOdometry::CheckExposure(const cv::Mat& image) const {
  cv::Scalar mean, stddev;
  cv::meanStdDev(image, mean, stddev);
  const ImageCheckOptions& c = options_.checks;
  if (mean[0] < c.min_mean_dn) return VoStatus::kBlackImage;
  if (mean[0] > c.max_mean_dn) return VoStatus::kOverExposed;
  if (stddev[0] < c.min_stddev_dn) return VoStatus::kTextureless;
  return VoStatus::kTracked;
}

StereoOdometry::Attempt StereoOdometry::TrackAgainst(
    int index, const std::optional<Eigen::Isometry3d>& T_cur_kf_guess, bool has_right,
    VoFrameResult* result) {
  Clock::time_point clock = Clock::now();
  const Keyframe& kf = keyframes_[static_cast<size_t>(index)];
  Attempt a;
  a.keyframe = index;
  // Start each track where the guess projects it, else where it was last seen.
  std::vector<cv::Point2f> guess = kf.last_pixels;
  if (T_cur_kf_guess) {
    const calib::RectifiedIntrinsics& k = rectifier_.intrinsics();
    for (size_t i = 0; i < kf.points_cam0rect.size(); ++i) {
      const Eigen::Vector3d p = *T_cur_kf_guess * kf.points_cam0rect[i];
      if (p.z() > 1e-3) {
        guess[i] = cv::Point2f(static_cast<float>(k.fx * p.x() / p.z() + k.cx),
                               static_cast<float>(k.fy * p.y() / p.z() + k.cy));
      }
    }
  }
  const TrackResult tracks = tracker_.TrackPyramids(kf.pyramid, pyramid0_, kf.pixels, guess);
  result->times.track_ms += Lap(&clock);

  std::vector<cv::Point2f> left, right;
  std::vector<int> point;
  for (size_t i = 0; i < kf.pixels.size(); ++i) {
    if (tracks.tracked[i] == 0) continue;
    left.push_back(tracks.points[i]);
    right.push_back(tracks.points[i] - cv::Point2f(kf.disparity_px[i], 0.0F));
    point.push_back(static_cast<int>(i));
  }
  a.tracked = static_cast<int>(left.size());
  std::vector<unsigned char> right_ok(left.size(), 0);
  if (has_right) MatchRight(left, &right, &right_ok);
  result->times.stereo_ms += Lap(&clock);

  a.observations.reserve(left.size());
  for (size_t j = 0; j < left.size(); ++j) {
    StereoObservation o;
    o.p_ref = kf.points_cam0rect[static_cast<size_t>(point[j])];
    o.p_ref_covariance = kf.point_covariances[static_cast<size_t>(point[j])];
    o.left = Eigen::Vector2d(left[j].x, left[j].y);
    o.has_right = right_ok[j] != 0;
    if (o.has_right) {
      o.right = Eigen::Vector2d(right[j].x, right[j].y);
      ++a.with_right;
    }
    a.observations.push_back(o);
  }
  a.point_of_observation = std::move(point);
  a.motion = motion_.Estimate(a.observations);
  result->times.ransac_ms += a.motion.ransac_ms;
  result->times.refine_ms += a.motion.refine_ms;
  return a;
}

void StereoOdometry::MatchRight(const std::vector<cv::Point2f>& left,
                                std::vector<cv::Point2f>* right,
                                std::vector<unsigned char>* ok) const {
  if (left.empty() || pyramid1_.empty()) return;
  const cv::Size window(options_.stereo_klt_window_px, options_.stereo_klt_window_px);
  const cv::TermCriteria term(cv::TermCriteria::COUNT | cv::TermCriteria::EPS,
                              options_.tracker.max_iterations, 0.01);
  std::vector<unsigned char> status, back_status;
  std::vector<float> error;
  cv::calcOpticalFlowPyrLK(pyramid0_, pyramid1_, left, *right, status, error, window,
                           options_.stereo_klt_levels, term, cv::OPTFLOW_USE_INITIAL_FLOW);
  std::vector<cv::Point2f> back = left;
  cv::calcOpticalFlowPyrLK(pyramid1_, pyramid0_, *right, back, back_status, error, window,
                           options_.stereo_klt_levels, term, cv::OPTFLOW_USE_INITIAL_FLOW);
  const StereoMatcherOptions& s = options_.stereo;
  const auto width = static_cast<float>(rectifier_.image_size().width);
  for (size_t j = 0; j < left.size(); ++j) {
    const cv::Point2f& r = (*right)[j];
    const auto disparity = static_cast<double>(left[j].x - r.x);
    const cv::Point2f fb = back[j] - left[j];
    (*ok)[j] = status[j] != 0 && back_status[j] != 0 && std::isfinite(r.x) && std::isfinite(r.y) &&
               r.x >= 0.0F && r.x < width &&
               static_cast<double>(std::abs(r.y - left[j].y)) <= s.max_row_error_px &&
               disparity >= s.min_disparity_px && disparity <= s.max_disparity_px &&
               std::sqrt(static_cast<double>(fb.dot(fb))) <= s.max_fb_error_px;
  }
}

bool StereoOdometry::NeedsKeyframe(const Attempt& a) const {
  const KeyframeOptions& k = options_.keyframes;
  const Keyframe& kf = keyframes_[static_cast<size_t>(a.keyframe)];
  const auto inliers = static_cast<double>(a.motion.inliers.size());
  return inliers < k.min_tracked_inliers ||
         inliers < k.min_tracked_fraction * static_cast<double>(kf.points_cam0rect.size()) ||
         a.motion.T_cur_ref.translation().norm() > k.max_translation_m ||
         RotationAngleRad(a.motion.T_cur_ref) > k.max_rotation_rad;
}

std::optional<StereoOdometry::Attempt> StereoOdometry::TryRevisit(const Attempt& current,
                                                                  bool has_right,
                                                                  VoFrameResult* result) {
  // Older keyframes the current frame should overlap with, nearest first,
  // predicted through the chained keyframe poses.
  const KeyframeOptions& k = options_.keyframes;
  const Keyframe& active = keyframes_[static_cast<size_t>(current.keyframe)];
  const double active_score = current.motion.T_cur_ref.translation().norm() / k.max_translation_m +
                              RotationAngleRad(current.motion.T_cur_ref) / k.max_rotation_rad;
  std::vector<std::pair<double, int>> candidates;
  for (int i = 0; i < static_cast<int>(keyframes_.size()); ++i) {
    if (i == current.keyframe) continue;
    const Eigen::Isometry3d T_cur_kf = current.motion.T_cur_ref * active.T_odom_cam.inverse() *
                                       keyframes_[static_cast<size_t>(i)].T_odom_cam;
    const double t = T_cur_kf.translation().norm() / k.max_translation_m;
    const double r = RotationAngleRad(T_cur_kf) / k.max_rotation_rad;
    // Only keyframes nearer than the active one are worth a try: driving on,
    // the older keyframes lie behind and each try would cost a KLT pass.
    if (t < 1.0 && r < 1.0 && t + r < active_score) candidates.emplace_back(t + r, i);
  }
  std::sort(candidates.begin(), candidates.end());
  constexpr size_t kMaxTries = 2;  // bounds the extra cost of a keyframe decision
  for (size_t c = 0; c < std::min(candidates.size(), kMaxTries); ++c) {
    const int i = candidates[c].second;
    const Eigen::Isometry3d T_cur_kf = current.motion.T_cur_ref * active.T_odom_cam.inverse() *
                                       keyframes_[static_cast<size_t>(i)].T_odom_cam;
    Attempt a = TrackAgainst(i, T_cur_kf, has_right, result);
    if (a.motion.valid && static_cast<int>(a.motion.inliers.size()) >= k.min_revisit_inliers &&
        a.motion.inliers.size() > current.motion.inliers.size() && !NeedsKeyframe(a)) {
      return a;
    }
  }
  return std::nullopt;
}

void StereoOdometry::RememberTracks(const Attempt& a, Keyframe* kf) const {
  // Next frame's KLT starts from here; points that were not inliers restart
  // from where the motion puts them.
  const calib::RectifiedIntrinsics& k = rectifier_.intrinsics();
  for (size_t i = 0; i < kf->points_cam0rect.size(); ++i) {
    const Eigen::Vector3d p = a.motion.T_cur_ref * kf->points_cam0rect[i];
    if (p.z() > 1e-3) {
      kf->last_pixels[i] = cv::Point2f(static_cast<float>(k.fx * p.x() / p.z() + k.cx),
                                       static_cast<float>(k.fy * p.y() / p.z() + k.cy));
    }
  }
  for (int j : a.motion.inliers) {
    const StereoObservation& o = a.observations[static_cast<size_t>(j)];
    kf->last_pixels[static_cast<size_t>(a.point_of_observation[static_cast<size_t>(j)])] =
        cv::Point2f(static_cast<float>(o.left.x()), static_cast<float>(o.left.y()));
  }
}

Eigen::Matrix3d StereoOdometry::PointCovariance(const Eigen::Vector3d& p,
                                                double disparity_px) const {
  // p = b / d * (u - cx, (v - cy) fx / fy, fx): first-order propagation of
  // the left pixel noise (sigma_d / sqrt(2) per axis, as each image
  // contributes half of the disparity variance) and of the disparity noise.
  const calib::RectifiedIntrinsics& k = rectifier_.intrinsics();
  const double b = rectifier_.baseline_m();
  const double sigma_d = options_.stereo.disparity_sigma_px;
  const double var_uv = 0.5 * sigma_d * sigma_d;
  Eigen::Matrix3d J;
  J.col(0) = Eigen::Vector3d(b / disparity_px, 0.0, 0.0);
  J.col(1) = Eigen::Vector3d(0.0, b * k.fx / (k.fy * disparity_px), 0.0);
  J.col(2) = -p / disparity_px;
  const Eigen::Vector3d var(var_uv, var_uv, sigma_d * sigma_d);
  return J * var.asDiagonal() * J.transpose();
}

bool StereoOdometry::AddStereoPoint(const cv::Point2f& left, const cv::Point2f& right,
                                    Keyframe* kf) const {
  const StereoMatcherOptions& s = options_.stereo;
  const auto disparity = static_cast<double>(left.x - right.x);
  if (!(disparity >= s.min_disparity_px)) return false;
  const Eigen::Vector3d p = matcher_.Triangulate(left, right);
  const double sigma_z = matcher_.DepthSigma(p.z());
  if (!p.allFinite() || p.z() <= 0.0 || sigma_z > s.max_depth_sigma_m ||
      sigma_z > s.max_relative_depth_sigma * p.z()) {
    return false;
  }
  kf->pixels.push_back(left);
  kf->disparity_px.push_back(static_cast<float>(disparity));
  kf->points_cam0rect.push_back(p);
  kf->point_covariances.push_back(PointCovariance(p, disparity));
  return true;
}

bool StereoOdometry::MakeKeyframe(Time capture, const Attempt* attempt,
                                  const Eigen::Isometry3d& T_odom_cam, VoFrameResult* result) {
  Clock::time_point clock = Clock::now();
  Keyframe kf;
  kf.capture = capture;
  kf.T_odom_cam = T_odom_cam;
  // Inliers that still have a right-image match keep their track, triangulated afresh.
  if (attempt != nullptr) {
    for (int j : attempt->motion.inliers) {
      const StereoObservation& o = attempt->observations[static_cast<size_t>(j)];
      if (!o.has_right) continue;
      AddStereoPoint(cv::Point2f(static_cast<float>(o.left.x()), static_cast<float>(o.left.y())),
                     cv::Point2f(static_cast<float>(o.right.x()), static_cast<float>(o.right.y())),
                     &kf);
    }
  }
  const int kept = static_cast<int>(kf.pixels.size());
  std::vector<cv::Point2f> fresh = detector_.Detect(rect0_, kf.pixels);
  const auto room = static_cast<size_t>(std::max(0, options_.max_features - kept));
  if (fresh.size() > room) fresh.resize(room);
  result->times.detect_ms += Lap(&clock);
  const std::vector<StereoPoint> matches = matcher_.Match(rect0_, rect1_, fresh);
  for (const StereoPoint& sp : matches) AddStereoPoint(sp.left, sp.right, &kf);
  result->times.stereo_ms += Lap(&clock);
  result->quality.new_features = static_cast<int>(kf.pixels.size()) - kept;
  if (static_cast<int>(kf.pixels.size()) < options_.keyframes.min_keyframe_points) return false;

  kf.last_pixels = kf.pixels;
  std::swap(kf.pyramid, pyramid0_);  // pyramid0_ is rebuilt for the next frame
  keyframes_.push_back(std::move(kf));
  if (static_cast<int>(keyframes_.size()) > options_.keyframes.max_keyframes) {
    keyframes_.pop_front();
  }
  active_ = static_cast<int>(keyframes_.size()) - 1;
  ++health_.keyframes;
  return true;
}

void StereoOdometry::FillQuality(const Attempt& a, VoFrameResult* result) const {
  VoQuality& q = result->quality;
  q.keyframe_points =
      static_cast<int>(keyframes_[static_cast<size_t>(active_)].points_cam0rect.size());
  q.tracked = a.tracked;
  q.with_right = a.with_right;
  q.inliers = static_cast<int>(a.motion.inliers.size());
  q.rms_error_px = a.motion.rms_error_px;
  q.spread = a.motion.spread;
  q.inflation = a.motion.inflation;
  q.ransac_iterations = a.motion.ransac_iterations;
}

void StereoOdometry::Finish(VoStatus status, std::chrono::steady_clock::time_point start,
                            VoFrameResult* result) {
  result->status = status;
  ++health_.by_status[static_cast<size_t>(status)];
  health_.last_status = status;
  health_.healthy = status == VoStatus::kTracked || status == VoStatus::kNewKeyframe ||
                    status == VoStatus::kRevisited || status == VoStatus::kFirstKeyframe;
  if (result->measurement) {
    ++health_.measurements;
    if (result->quality.inflation > 1.0) ++health_.inflated;
  }
  result->times.total_ms = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

}  // namespace rover::estimator::vo
