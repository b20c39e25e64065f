#ifndef ROVER_MAPPING_DEPTH_STEREO_ERROR_MODEL_H_
#define ROVER_MAPPING_DEPTH_STEREO_ERROR_MODEL_H_

// First-order stereo reconstruction error (thesis section 5.1.1, after
// Hirschmüller 2003 / Hirschmüller et al. 2002). Each point is reconstructed
// from four image coordinates, (u_l, v_l) in the left and (u_r, v_r) in the
// right image, each with independent Gaussian noise of `pixel_error_px`
// (the thesis uses 0.5 px from its calibration RMSE); the rectified row is
// v = (v_l + v_r) / 2. Propagating through the triangulation gives the
// thesis's equation 5.2:
//   sigma_x = dp z / (f b) sqrt((b - x)^2 + x^2)
//   sigma_y = dp z / (f b) sqrt(2 y^2 + b^2 / 2)
//   sigma_z = dp z^2 / (f b) sqrt(2)
//
// The error of the distance between two points (equation 5.4, used for the
// error-adaptive step threshold) is propagated the same way, through
// d = |p - q| and both points' eight image coordinates. The thesis's printed
// 5.4b has a "t" where the baseline b belongs; deriving it again from the
// Jacobian, as here, avoids carrying the typo (the tests compare against a
// numeric derivative and a seeded Monte Carlo).
//
// The step classifier thresholds a height difference, not a distance, so
// it takes the error of that height difference instead (propagated the same
// way, onto the vertical). The two agree for points stacked vertically; for
// two cells side by side across the line of sight, the distance between
// them hardly depends on the depth error, while their heights do: at 3.5 m
// on the simulator's head Delta d is about 1 cm, the height difference's
// error 8 cm.

#include <Eigen/Core>

#include "mapping/depth/rectified_stereo.h"

namespace rover::mapping {

class StereoErrorModel {
 public:
  /// Throws std::invalid_argument for an unusable geometry or a pixel error
  /// that is not positive.
  StereoErrorModel(const RectifiedStereo& stereo, double pixel_error_px = 0.5);

  /// d p / d (u_l, v_l, u_r, v_r) of the point p (left camera frame). Exact
  /// for the pinhole triangulation; p must have z > 0.
  Eigen::Matrix<double, 3, 4> PointJacobian(const Eigen::Vector3d& p) const;

  /// (sigma_x, sigma_y, sigma_z) of a reconstructed point, metres.
  Eigen::Vector3d PointSigma(const Eigen::Vector3d& p) const;

  /// sigma_z alone (the quantity points are filtered on).
  double DepthSigma(double z_m) const {
    return pixel_error_px_ * z_m * z_m / (stereo_.focal_px * stereo_.baseline_m) * kSqrt2;
  }

  /// First-order standard error of |p - q| for two independently matched
  /// points (thesis eq. 5.4, Delta d). Zero when p == q.
  double DistanceSigma(const Eigen::Vector3d& p, const Eigen::Vector3d& q) const;

  /// First-order standard error of the height difference (p - q) . up of
  /// two independently matched points, `up_cam` the unit up direction in
  /// the camera frame. Unlike DistanceSigma it does not vanish for p == q.
  double HeightDifferenceSigma(const Eigen::Vector3d& p, const Eigen::Vector3d& q,
                               const Eigen::Vector3d& up_cam) const;

  const RectifiedStereo& stereo() const { return stereo_; }
  double pixel_error_px() const { return pixel_error_px_; }

 private:
  static constexpr double kSqrt2 = 1.4142135623730951;
  RectifiedStereo stereo_;
  double pixel_error_px_;
};

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_DEPTH_STEREO_ERROR_MODEL_H_
