#ifndef ROVER_ESTIMATOR_VO_STEREO_RECTIFIER_H_
#define ROVER_ESTIMATOR_VO_STEREO_RECTIFIER_H_

// Stereo rectification for the VO front end. The undistort/rectify maps are
// computed once from the calibration; every frame is then remapped with them.
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

namespace rover::estimator::vo {

/// Pinhole + radial-tangential camera as the calibration gives it.
struct CameraModel {
  int width_px = 0;
  int height_px = 0;
  std::array<double, 4> intrinsics{};  ///< fu, fv, cu, cv [px]
  std::array<double, 4> distortion{};  ///< k1, k2, p1, p2
  Eigen::Isometry3d T_body_cam = Eigen::Isometry3d::Identity();
};

struct StereoRectifierOptions {
  /// OpenCV's free scaling: 0 keeps only valid pixels, 1 keeps all source pixels.
  double alpha = 0.0;
};

/// Rectified pinhole intrinsics shared by both rectified images.
struct RectifiedIntrinsics {
  double fx = 0.0;
  double fy = 0.0;
  double cx = 0.0;
  double cy = 0.0;
};

class StereoRectifier {
 public:
  /// Computes the rectification and the remap tables. Returns nullopt when the
  /// calibration is unusable (sizes differ or are zero, focal lengths not
  /// positive, cameras coincide or cam1 is not to the right of cam0).
  static std::optional<StereoRectifier> Create(const CameraModel& cam0, const CameraModel& cam1,
                                               const StereoRectifierOptions& options = {});

  /// Remaps a raw 8-bit grey image pair. Returns false (outputs untouched) when
  /// either image is empty, of the wrong size or not CV_8UC1.
  bool Rectify(const cv::Mat& raw0, const cv::Mat& raw1, cv::Mat* rect0, cv::Mat* rect1) const;
  /// Remaps one raw image of camera `index` (0 or 1); false on bad input.
  bool RectifyOne(int index, const cv::Mat& raw, cv::Mat* rect) const;

  const RectifiedIntrinsics& intrinsics() const { return intrinsics_; }
  /// Distance between the rectified optical centres [m] (> 0).
  double baseline_m() const { return baseline_m_; }
  cv::Size image_size() const { return size_; }
  /// Pose of the body in the rectified cam0 frame.
  const Eigen::Isometry3d& T_cam0rect_body() const { return T_cam0rect_body_; }
  Eigen::Isometry3d T_body_cam0rect() const { return T_cam0rect_body_.inverse(); }

 private:
  StereoRectifier() = default;

  cv::Size size_;
  std::array<cv::Mat, 2> map_a_;
  std::array<cv::Mat, 2> map_b_;
  RectifiedIntrinsics intrinsics_;
  double baseline_m_ = 0.0;
  Eigen::Isometry3d T_cam0rect_body_ = Eigen::Isometry3d::Identity();
};

}  // namespace rover::estimator::vo

#endif  // ROVER_ESTIMATOR_VO_STEREO_RECTIFIER_H_
