#ifndef ROVER_CORE_CALIB_STEREO_RECTIFIER_H_
#define ROVER_CORE_CALIB_STEREO_RECTIFIER_H_

// Stereo rectification for the VO front end and the mapper. The
// undistort/rectify maps are computed once from the calibration; every frame
// is then remapped with them.
//
// Frames: `cam0rect` is cam0 rotated so that both rectified cameras share the
// same orientation and image rows (OpenCV axes: x right, y down, z forward).
// `cam1rect` is cam0rect shifted by `baseline_m` along +x. Both rectified
// images use the same pinhole matrix (fx, fy, cx, cy) and no distortion.

#include <opencv2/core.hpp>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <optional>

#include "core/calib/camera_model.h"

namespace rover::calib {

/// How the rectified images are framed.
struct StereoRectifierOptions {
  /// OpenCV's free scaling: 0 keeps only valid pixels, 1 keeps all source
  /// pixels. For equidistant (fisheye) cameras it is OpenCV's `balance`,
  /// which moves the focal length between the same two extremes.
  double alpha = 0.0;
};

/// Rectified pinhole intrinsics shared by both rectified images.
struct RectifiedIntrinsics {
  double fx = 0.0;
  double fy = 0.0;
  double cx = 0.0;
  double cy = 0.0;
};

/// Rectification of one stereo head: remap tables for both cameras and the
/// rectified geometry.
class StereoRectifier {
 public:
  /// Computes the rectification and the remap tables. Returns nullopt when the
  /// calibration is unusable (sizes differ or are zero, focal lengths not
  /// positive, the two cameras use different distortion models, cameras
  /// coincide or cam1 is not to the right of cam0). Radial-tangential heads
  /// go through cv::stereoRectify and cv::initUndistortRectifyMap,
  /// equidistant ones through their cv::fisheye counterparts.
  static std::optional<StereoRectifier> Create(const CameraModel& cam0, const CameraModel& cam1,
                                               const StereoRectifierOptions& options = {});

  /// Remaps a raw 8-bit grey image pair and undoes each camera's vignetting
  /// (CameraModel::vignetting_cos4_strength; brightened values saturate at
  /// 255), so that a point keeps its brightness across the image and between
  /// the two cameras. Returns false (outputs untouched) when either image is
  /// empty, of the wrong size or not CV_8UC1.
  bool Rectify(const cv::Mat& raw0, const cv::Mat& raw1, cv::Mat* rect0, cv::Mat* rect1) const;
  /// Remaps one raw image of camera `index` (0 or 1); false on bad input.
  bool RectifyOne(int index, const cv::Mat& raw, cv::Mat* rect) const;

  /// The gain by which RectifyOne(index) brightens each rectified pixel of
  /// camera `index` (0 or 1) to undo its vignetting, CV_32FC1 of
  /// image_size(); empty when that camera has none (or for a bad index).
  /// Sensor noise is brightened with the signal: a threshold on rectified
  /// intensities that is meant in sensor counts scales by it.
  cv::Mat FlatFieldGain(int index) const;

  /// The pinhole matrix of both rectified images.
  const RectifiedIntrinsics& intrinsics() const { return intrinsics_; }
  /// Distance between the rectified optical centres [m] (> 0).
  double baseline_m() const { return baseline_m_; }
  /// Size of the raw and of the rectified images.
  cv::Size image_size() const { return size_; }
  /// Pose of the body in the rectified cam0 frame.
  const Eigen::Isometry3d& T_cam0rect_body() const { return T_cam0rect_body_; }
  /// Pose of the rectified cam0 frame in the body frame.
  Eigen::Isometry3d T_body_cam0rect() const { return T_cam0rect_body_.inverse(); }

 private:
  StereoRectifier() = default;
  /// The gain map of one camera (see flat_field_q8_) from its rectifying
  /// rotation R_rect_cam and the rectified intrinsics.
  static cv::Mat FlatFieldGainQ8(const CameraModel& cam, const Eigen::Matrix3d& R_rect_cam,
                                 const RectifiedIntrinsics& k, cv::Size size);

  cv::Size size_;
  std::array<cv::Mat, 2> map_a_;
  std::array<cv::Mat, 2> map_b_;
  /// Per rectified pixel, the gain that undoes the vignetting, 8.8 fixed
  /// point (CV_16UC1); empty for a flat-field camera.
  std::array<cv::Mat, 2> flat_field_q8_;
  RectifiedIntrinsics intrinsics_;
  double baseline_m_ = 0.0;
  Eigen::Isometry3d T_cam0rect_body_ = Eigen::Isometry3d::Identity();
};

}  // namespace rover::calib

#endif  // ROVER_CORE_CALIB_STEREO_RECTIFIER_H_
