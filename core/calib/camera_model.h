#ifndef ROVER_CORE_CALIB_CAMERA_MODEL_H_
#define ROVER_CORE_CALIB_CAMERA_MODEL_H_

// The calibrated model of one camera: image size, rate, pinhole intrinsics,
// lens distortion and the camera's pose on the body.
//
// Frames follow OpenCV (x right, y down, z forward). Pixel coordinates have
// their origin at the centre of the top-left pixel, as in OpenCV, so
// Project() agrees with cv::projectPoints (radial-tangential) and
// cv::fisheye::projectPoints (equidistant).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <optional>
#include <string_view>

#include "core/calib/validation.h"

namespace rover::calib {

/// How the lens bends rays. Both act on the normalised image coordinates
/// (x, y) = (X / Z, Y / Z) of a point in the camera frame.
enum class DistortionModel {
  /// Brown-Conrady, coefficients k1 k2 p1 p2 (OpenCV's first four; Kalibr's
  /// and EuRoC's "radial-tangential", "radtan").
  kRadialTangential,
  /// Kannala-Brandt equidistant, coefficients k1 k2 k3 k4 on the angle theta
  /// from the optical axis: theta_d = theta (1 + k1 theta^2 + ... + k4 theta^8)
  /// (OpenCV's fisheye module; Kalibr's "equidistant").
  kEquidistant,
};

/// The distortion model's name in EuRoC/Kalibr sensor.yaml files:
/// "radial-tangential" or "equidistant".
std::string_view EurocDistortionName(DistortionModel model);

/// One camera's calibration.
struct CameraModel {
  int width_px = 0;
  int height_px = 0;
  /// Nominal frame rate [Hz]; 0 where nobody said (e.g. a model built in a
  /// test), which Validate() rejects.
  double rate_hz = 0.0;
  DistortionModel distortion_model = DistortionModel::kRadialTangential;
  std::array<double, 4> intrinsics{};  ///< fu, fv, cu, cv [px]
  /// k1 k2 p1 p2 (radial-tangential) or k1 k2 k3 k4 (equidistant).
  std::array<double, 4> distortion{};
  Eigen::Isometry3d T_body_cam = Eigen::Isometry3d::Identity();
  /// Vignetting (the lens darkens the image towards its edges): the relative
  /// brightness of a pixel whose ray is theta off the optical axis is
  /// 1 - v (1 - cos^4 theta), v this strength in [0, 1); 0: a flat field.
  /// Trackers that assume a point keeps its brightness (KLT) are biased by
  /// it, so the rectifier undoes it.
  double vignetting_cos4_strength = 0.0;

  /// The pixel at which the point `p_cam` (camera frame, metres or any unit)
  /// is seen, or nullopt for a point not in front of the camera (z <= 0 or
  /// not finite). Distortion is applied as OpenCV applies it; far outside
  /// the calibrated field of view the polynomial may fold back, so a result
  /// there is not meaningful.
  std::optional<Eigen::Vector2d> Project(const Eigen::Vector3d& p_cam) const;

  /// The unit bearing (camera frame, z > 0) of the ray seen at `pixel`: the
  /// inverse of Project(). Nullopt where the distortion cannot be inverted
  /// (past the radius at which the model folds back, or no convergence).
  std::optional<Eigen::Vector3d> Unproject(const Eigen::Vector2d& pixel) const;

  /// The first unusable field ("width_px", "height_px", "rate_hz",
  /// "intrinsics", "distortion", "T_body_cam", "vignetting_cos4_strength")
  /// and why, or nullopt: sizes and rate must be positive, focal lengths
  /// positive, every number finite, T_body_cam a rigid transform
  /// (RigidTransformProblem), the vignetting strength in [0, 1).
  std::optional<FieldProblem> Problem() const;

  /// Throws std::invalid_argument "field: expected ..., found ..." if
  /// Problem() finds one.
  void Validate() const;

  /// Exact equality of every field (T_body_cam element by element).
  friend bool operator==(const CameraModel& a, const CameraModel& b);
};

}  // namespace rover::calib

#endif  // ROVER_CORE_CALIB_CAMERA_MODEL_H_
