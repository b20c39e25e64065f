#ifndef ROVER_ESTIMATOR_VO_MOTION_ESTIMATOR_H_
#define ROVER_ESTIMATOR_VO_MOTION_ESTIMATOR_H_

// Relative camera motion from 3-D points of a reference (keyframe) stereo pair
// and their observations in the current rectified stereo pair:
//  1. RANSAC over minimal P3P samples (left image), each hypothesis scored by
//     the reprojection error in both current images; fixed seed, no threads.
//  2. Levenberg-Marquardt on the reprojection error in both images over the
//     inliers, with the analytic Jacobian of ReprojectionResidual().
//  3. Covariance: the inverse Gauss-Newton Hessian scaled by the residual
//     variance, inflated when there are few inliers or they cover little of
//     the image.
//
// Pose and perturbation convention: the estimate is T_cur_ref (points of the
// reference rectified cam0 frame into the current one); its covariance is over
// a LEFT perturbation xi = (rho, phi), translation first:
// T_est = ExpSE3(xi) * T_true.

#include <opencv2/core.hpp>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "core/calib/stereo_rectifier.h"
#include "estimator/eskf/eskf_input.h"

namespace rover::estimator::vo {

/// A reference point and where it is seen in the current rectified pair.
struct StereoObservation {
  Eigen::Vector3d p_ref = Eigen::Vector3d::Zero();  ///< reference cam0rect frame [m]
  Eigen::Vector2d left = Eigen::Vector2d::Zero();   ///< current left pixel
  Eigen::Vector2d right = Eigen::Vector2d::Zero();  ///< current right pixel
  bool has_right = true;                            ///< false: left image only
  /// Uncertainty of p_ref (from the reference pair's triangulation) [m^2];
  /// zero treats the point as exact. Enters the covariance only.
  Eigen::Matrix3d p_ref_covariance = Eigen::Matrix3d::Zero();
};

struct MotionEstimatorOptions {
  int ransac_max_iterations = 300;
  double ransac_confidence = 0.999;
  double inlier_threshold_px = 2.0;  ///< in each image
  uint64_t seed = 0x5eed;
  int min_inliers = 12;  ///< fewer: no estimate
  int lm_max_iterations = 20;
  /// Noise of a tracked feature position in each image [px]. With the
  /// points' own uncertainty it weights the refinement; the covariance is
  /// scaled up when the whitened residuals are larger.
  double pixel_sigma_px = 0.1;
  int good_inliers = 60;     ///< fewer inliers inflate the covariance by good/actual
  double good_spread = 0.5;  ///< lower coverage inflates it by good/actual
  int spread_grid = 4;       ///< coverage = occupied cells of a grid x grid partition
  /// Final factor on the covariance for what the model leaves out: KLT
  /// errors of neighbouring features are correlated (their windows overlap
  /// and see the same pixel noise), while the model treats them as
  /// independent. Calibrated on simulated drives so that the NEES of the
  /// emitted relative poses matches its 6 degrees of freedom.
  double covariance_scale = 1.0;
};

/// Result of Estimate(); `valid` false means no usable motion.
struct MotionEstimate {
  bool valid = false;
  Eigen::Isometry3d T_cur_ref = Eigen::Isometry3d::Identity();
  Matrix6d covariance = Matrix6d::Identity();  ///< left perturbation (rho, phi) of T_cur_ref
  std::vector<int> inliers;                    ///< indices into the observations
  int observations = 0;
  int ransac_iterations = 0;
  int lm_iterations = 0;
  double rms_error_px = 0.0;  ///< over the inlier residuals after refinement
  double spread = 0.0;        ///< image coverage of the inliers in [0, 1]
  double inflation = 1.0;     ///< factor applied to the covariance
  /// sqrt of the whitened residual variance, at least 1: how much larger the
  /// residuals are than the noise model (the covariance is scaled by its square).
  double residual_scale = 1.0;
  double ransac_ms = 0.0;  ///< wall time of the RANSAC stage (informative only)
  double refine_ms = 0.0;  ///< wall time of refinement and covariance (informative only)
};

class MotionEstimator {
 public:
  MotionEstimator(const calib::RectifiedIntrinsics& intrinsics, double baseline_m,
                  cv::Size image_size, const MotionEstimatorOptions& options = {});

  /// Estimates T_cur_ref. Deterministic for the same input and options.
  MotionEstimate Estimate(const std::vector<StereoObservation>& observations) const;

  /// Levenberg-Marquardt refinement of T_cur_ref over `indices`; returns the
  /// number of iterations run.
  int Refine(const std::vector<StereoObservation>& observations, const std::vector<int>& indices,
             Eigen::Isometry3d* T_cur_ref) const;

  /// Residual predicted - measured (u_l, v_l, u_r, v_r) [px] of one
  /// observation and, if `jacobian` is set, its derivative with respect to a
  /// left perturbation of T_cur_ref. Rows 2..3 are zero without a right
  /// observation. Returns false when the point is not in front of the camera.
  /// If `point_jacobian` is set, also the derivative with respect to p_ref.
  bool ReprojectionResidual(const Eigen::Isometry3d& T_cur_ref, const StereoObservation& obs,
                            Eigen::Vector4d* residual,
                            Eigen::Matrix<double, 4, 6>* jacobian = nullptr,
                            Eigen::Matrix<double, 4, 3>* point_jacobian = nullptr) const;

  const MotionEstimatorOptions& options() const { return options_; }

 private:
  bool IsInlier(const Eigen::Isometry3d& T, const StereoObservation& obs) const;
  double Spread(const std::vector<StereoObservation>& observations,
                const std::vector<int>& indices) const;
  /// Inverse covariance of an observation's residuals: pixel noise plus the
  /// reference point's uncertainty projected at T_cur_ref (2x2 block only
  /// without a right observation; zero when the point is behind the camera).
  Eigen::Matrix4d ObservationWeight(const Eigen::Isometry3d& T_cur_ref,
                                    const StereoObservation& obs) const;

  calib::RectifiedIntrinsics k_;
  double baseline_m_;
  cv::Size size_;
  MotionEstimatorOptions options_;
};

/// Body-frame relative pose in the filter's convention (RelativePoseMeasurement):
/// from T_cur_ref and its left-perturbation covariance (as MotionEstimate
/// gives them) and the rectified camera extrinsics T_body_cam0rect, returns
/// T_bodyref_bodycur with Cov([n_p; n_theta]), p_meas = p + n_p,
/// R_meas = R Exp(n_theta). Stamps are left for the caller.
RelativePoseMeasurement ToBodyRelativePose(const Eigen::Isometry3d& T_cur_ref,
                                           const Matrix6d& covariance_cam,
                                           const Eigen::Isometry3d& T_body_cam0rect);

}  // namespace rover::estimator::vo

#endif  // ROVER_ESTIMATOR_VO_MOTION_ESTIMATOR_H_
