#ifndef ROVER_MAPPING_DEPTH_RECTIFIED_STEREO_H_
#define ROVER_MAPPING_DEPTH_RECTIFIED_STEREO_H_

// The geometry of a rectified stereo pair as mapping sees it: both images
// share the pinhole intrinsics, rows are epipolar lines, and the right
// camera sits `baseline_m` along the left camera's x axis. Points are in the
// left (rectified) camera frame, OpenCV axes: x right, y down, z forward.
//
// A point p and its observation (u_l, v, u_r), disparity d = u_l - u_r:
//   p = (b (u_l - cx) / d,  b (v - cy) / d,  f b / d)

#include <string>

#include <Eigen/Core>

namespace rover::mapping {

struct RectifiedStereo {
  int width_px = 0;
  int height_px = 0;
  double focal_px = 0.0;  ///< f, same for both axes after rectification
  double cx_px = 0.0;
  double cy_px = 0.0;
  double baseline_m = 0.0;  ///< b > 0

  /// Empty if usable, else "what: expected ..., found ...".
  std::string Problem() const;
  /// Throws std::invalid_argument with Problem().
  void Validate() const;

  /// The point seen at left column u_l, row v with disparity d (> 0).
  Eigen::Vector3d Triangulate(double u_l_px, double v_px, double disparity_px) const {
    const double z = focal_px * baseline_m / disparity_px;
    return {(u_l_px - cx_px) * z / focal_px, (v_px - cy_px) * z / focal_px, z};
  }
};

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_DEPTH_RECTIFIED_STEREO_H_
