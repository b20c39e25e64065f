#ifndef ROVER_HIL_SIM_RENDER_STEREO_CAMERA_H_
#define ROVER_HIL_SIM_RENDER_STEREO_CAMERA_H_

// The simulated stereo head: a hardware-triggered pair of identical global
// shutter cameras (pinhole + radial-tangential distortion) on a fixed
// baseline, and the sensor model that turns scene radiance into 8-bit
// pixels. The same struct is written to sensor.yaml, so what the renderer
// uses is exactly what the calibration says.
//
// Frames: body is x forward, y left, z up; cam0 (left) and cam1 (right)
// follow OpenCV axes (x right, y down, z forward). cam1 = cam0 moved by
// baseline_m along cam0's +x, with the same orientation. Pixel coordinates
// follow OpenCV: the centre of pixel (u, v) is at (u, v).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>

#include "core/calib/camera_model.h"
#include "core/config/config.h"

namespace rover::sim {

/// The default mount: cam0 at (0.3, 0.045, 0.5) m in body, looking forward and
/// pitched 20 deg down (terrain close to the rover fills the lower image).
Eigen::Isometry3d DefaultTBodyCam0();

struct StereoCameraOptions {
  // Geometry. Intrinsics and distortion are shared by both cameras; the
  // defaults are a mild wide-angle lens like the EuRoC MAV cameras.
  int width_px = 752;   ///< up to 1292
  int height_px = 480;  ///< up to 964
  double fx_px = 460.0;
  double fy_px = 460.0;
  double cx_px = 375.5;
  double cy_px = 239.5;
  double k1 = -0.28;  ///< radial, OpenCV order k1 k2 p1 p2
  double k2 = 0.07;
  double p1 = 2.0e-4;  ///< tangential
  double p2 = 2.0e-5;
  double baseline_m = 0.09;
  Eigen::Isometry3d T_body_cam0 = DefaultTBodyCam0();
  double rate_hz = 10.0;  ///< trigger rate, 10 .. 20 Hz

  // Sensor model. digital number = radiance * exposure_time_s * gain *
  // sensitivity_dn_per_s, where radiance 1 is a white Lambertian surface
  // facing the sun.
  double exposure_time_s = 0.007;
  double gain = 1.0;
  double sensitivity_dn_per_s = 50000.0;
  double read_noise_dn = 1.0;  ///< Gaussian read noise sigma, after gain
  /// Shot noise: variance in DN^2 = gain * dn_per_electron * signal_dn.
  double dn_per_electron = 0.05;
  /// 0: none; 1: full cos^4 falloff of the ray angle off the optical axis.
  double vignetting_strength = 0.5;

  // Ground-truth depth.
  double near_m = 0.05;       ///< near clip plane
  double max_depth_m = 60.0;  ///< ground-truth depth beyond this is reported invalid (0)

  /// Reads the options from a config section; every key is optional and
  /// defaults to the values above. T_body_cam0 is a 4x4 matrix.
  static StereoCameraOptions Load(const ConfigNode& node);
  /// Throws std::invalid_argument naming the first bad field.
  void Validate() const;

  Eigen::Isometry3d T_body_cam1() const;
  /// Pose of cam1 in cam0: a pure translation of +baseline_m along x.
  Eigen::Isometry3d T_cam0_cam1() const;
  /// 3x3 intrinsic matrix, row-major [fx 0 cx; 0 fy cy; 0 0 1].
  Eigen::Matrix3d CameraMatrix() const;
  /// OpenCV order: k1, k2, p1, p2.
  std::array<double, 4> DistortionCoeffs() const;
};

/// Radial-tangential distortion of normalised image coordinates (x/z, y/z).
Eigen::Vector2d DistortNormalized(const StereoCameraOptions& camera, const Eigen::Vector2d& xy_u);

/// Inverts DistortNormalized by Newton's method. Returns false if it did not
/// converge to 1e-12 (only far outside any sensible field of view).
bool UndistortNormalized(const StereoCameraOptions& camera, const Eigen::Vector2d& xy_d,
                         Eigen::Vector2d* xy_u);

/// Projects a point in camera coordinates to distorted pixel coordinates.
/// Returns false if the point is not in front of the camera.
bool ProjectToPixel(const StereoCameraOptions& camera, const Eigen::Vector3d& p_cam,
                    Eigen::Vector2d* uv_px);

/// The unit ray (camera coordinates) through a distorted pixel.
bool PixelToRay(const StereoCameraOptions& camera, const Eigen::Vector2d& uv_px,
                Eigen::Vector3d* ray_cam);

/// What a calibration of the simulated camera at `T_body_cam` states (its
/// size, rate, intrinsics and lens): the model roverd, mapd and a generated
/// dataset's sensor.yaml all use.
calib::CameraModel CameraModelOf(const StereoCameraOptions& camera,
                                 const Eigen::Isometry3d& T_body_cam);

}  // namespace rover::sim

#endif  // ROVER_HIL_SIM_RENDER_STEREO_CAMERA_H_
