#include "hil/sim/render/stereo_camera.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace rover::sim {

Eigen::Isometry3d DefaultTBodyCam0() {
  constexpr double kPitchDownRad = 20.0 * M_PI / 180.0;
  const double c = std::cos(kPitchDownRad);
  const double s = std::sin(kPitchDownRad);
  // Columns are the camera axes expressed in body: x right (= -y_body),
  // y down (perpendicular to the pitched optical axis), z along the optical axis.
  Eigen::Matrix3d R_body_cam;
  R_body_cam.col(0) = Eigen::Vector3d(0.0, -1.0, 0.0);
  R_body_cam.col(1) = Eigen::Vector3d(-s, 0.0, -c);
  R_body_cam.col(2) = Eigen::Vector3d(c, 0.0, -s);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = R_body_cam;
  T.translation() = Eigen::Vector3d(0.3, 0.045, 0.5);
  return T;
}

StereoCameraOptions StereoCameraOptions::Load(const ConfigNode& node) {
  StereoCameraOptions o;
  o.width_px = node.GetInRange<int>("width_px", 16, 1292, o.width_px);
  o.height_px = node.GetInRange<int>("height_px", 16, 964, o.height_px);
  o.fx_px = node.GetInRange<double>("fx_px", 1.0, 1e5, o.fx_px);
  o.fy_px = node.GetInRange<double>("fy_px", 1.0, 1e5, o.fy_px);
  o.cx_px = node.Get<double>("cx_px", o.cx_px);
  o.cy_px = node.Get<double>("cy_px", o.cy_px);
  o.k1 = node.Get<double>("k1", o.k1);
  o.k2 = node.Get<double>("k2", o.k2);
  o.p1 = node.Get<double>("p1", o.p1);
  o.p2 = node.Get<double>("p2", o.p2);
  o.baseline_m = node.GetInRange<double>("baseline_m", 0.001, 10.0, o.baseline_m);
  if (node.Has("T_body_cam0")) {
    o.T_body_cam0.matrix() = node.Get<Eigen::Matrix4d>("T_body_cam0");
  }
  o.rate_hz = node.GetInRange<double>("rate_hz", 10.0, 20.0, o.rate_hz);
  o.exposure_time_s = node.GetInRange<double>("exposure_time_s", 1e-6, 1.0, o.exposure_time_s);
  o.gain = node.GetInRange<double>("gain", 0.01, 100.0, o.gain);
  o.sensitivity_dn_per_s =
      node.GetInRange<double>("sensitivity_dn_per_s", 0.0, 1e9, o.sensitivity_dn_per_s);
  o.read_noise_dn = node.GetInRange<double>("read_noise_dn", 0.0, 100.0, o.read_noise_dn);
  o.dn_per_electron = node.GetInRange<double>("dn_per_electron", 0.0, 100.0, o.dn_per_electron);
  o.vignetting_strength =
      node.GetInRange<double>("vignetting_strength", 0.0, 1.0, o.vignetting_strength);
  o.near_m = node.GetInRange<double>("near_m", 1e-3, 10.0, o.near_m);
  o.max_depth_m = node.GetInRange<double>("max_depth_m", 0.1, 1e4, o.max_depth_m);
  o.Validate();
  return o;
}

void StereoCameraOptions::Validate() const {
  auto fail = [](const std::string& what) {
    throw std::invalid_argument("StereoCameraOptions: " + what);
  };
  if (width_px < 16 || width_px > 1292) fail("width_px must be in [16, 1292]");
  if (height_px < 16 || height_px > 964) fail("height_px must be in [16, 964]");
  if (!(fx_px > 0.0) || !(fy_px > 0.0)) fail("fx_px and fy_px must be positive");
  if (!(baseline_m > 0.0)) fail("baseline_m must be positive");
  if (!(rate_hz >= 10.0 && rate_hz <= 20.0)) fail("rate_hz must be in [10, 20]");
  if (!(exposure_time_s > 0.0)) fail("exposure_time_s must be positive");
  if (!(gain > 0.0)) fail("gain must be positive");
  if (!(read_noise_dn >= 0.0) || !(dn_per_electron >= 0.0)) fail("noise must be >= 0");
  if (!(vignetting_strength >= 0.0 && vignetting_strength <= 1.0)) {
    fail("vignetting_strength must be in [0, 1]");
  }
  if (!(near_m > 0.0) || !(max_depth_m > near_m)) fail("need 0 < near_m < max_depth_m");
  const Eigen::Matrix3d R = T_body_cam0.linear();
  if (!(R.transpose() * R).isIdentity(1e-6) || R.determinant() < 0.0) {
    fail("T_body_cam0 rotation is not a rotation");
  }
  // The renderer needs to invert the distortion at every image corner.
  for (const double u : {0.0, static_cast<double>(width_px - 1)}) {
    for (const double v : {0.0, static_cast<double>(height_px - 1)}) {
      Eigen::Vector3d ray;
      if (!PixelToRay(*this, Eigen::Vector2d(u, v), &ray)) {
        fail("distortion is not invertible at the image corners");
      }
    }
  }
}

Eigen::Isometry3d StereoCameraOptions::T_body_cam1() const { return T_body_cam0 * T_cam0_cam1(); }

Eigen::Isometry3d StereoCameraOptions::T_cam0_cam1() const {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(baseline_m, 0.0, 0.0);
  return T;
}

Eigen::Matrix3d StereoCameraOptions::CameraMatrix() const {
  Eigen::Matrix3d K;
  K << fx_px, 0.0, cx_px, 0.0, fy_px, cy_px, 0.0, 0.0, 1.0;
  return K;
}

std::array<double, 4> StereoCameraOptions::DistortionCoeffs() const { return {k1, k2, p1, p2}; }

Eigen::Vector2d DistortNormalized(const StereoCameraOptions& camera, const Eigen::Vector2d& xy_u) {
  const double x = xy_u.x();
  const double y = xy_u.y();
  const double r2 = x * x + y * y;
  const double radial = 1.0 + camera.k1 * r2 + camera.k2 * r2 * r2;
  return {x * radial + 2.0 * camera.p1 * x * y + camera.p2 * (r2 + 2.0 * x * x),
          y * radial + camera.p1 * (r2 + 2.0 * y * y) + 2.0 * camera.p2 * x * y};
}

bool UndistortNormalized(const StereoCameraOptions& camera, const Eigen::Vector2d& xy_d,
                         Eigen::Vector2d* xy_u) {
  // Newton on f(p) = Distort(p) - xy_d, started at xy_d; the Jacobian is
  // analytic, so a handful of steps reach machine precision.
  Eigen::Vector2d p = xy_d;
  for (int iteration = 0; iteration < 50; ++iteration) {
    const double x = p.x();
    const double y = p.y();
    const double r2 = x * x + y * y;
    const double radial = 1.0 + camera.k1 * r2 + camera.k2 * r2 * r2;
    const double dradial_dr2 = camera.k1 + 2.0 * camera.k2 * r2;
    Eigen::Matrix2d J;
    J(0, 0) = radial + 2.0 * x * x * dradial_dr2 + 2.0 * camera.p1 * y + 6.0 * camera.p2 * x;
    J(0, 1) = 2.0 * x * y * dradial_dr2 + 2.0 * camera.p1 * x + 2.0 * camera.p2 * y;
    J(1, 0) = 2.0 * x * y * dradial_dr2 + 2.0 * camera.p1 * x + 2.0 * camera.p2 * y;
    J(1, 1) = radial + 2.0 * y * y * dradial_dr2 + 6.0 * camera.p1 * y + 2.0 * camera.p2 * x;
    const Eigen::Vector2d residual = DistortNormalized(camera, p) - xy_d;
    if (residual.norm() < 1e-12) {
      *xy_u = p;
      return true;
    }
    if (std::abs(J.determinant()) < 1e-9) return false;
    p -= J.inverse() * residual;
  }
  return false;
}

bool ProjectToPixel(const StereoCameraOptions& camera, const Eigen::Vector3d& p_cam,
                    Eigen::Vector2d* uv_px) {
  if (!(p_cam.z() > 0.0)) return false;
  const Eigen::Vector2d xy_d = DistortNormalized(camera, p_cam.head<2>() / p_cam.z());
  *uv_px = {camera.fx_px * xy_d.x() + camera.cx_px, camera.fy_px * xy_d.y() + camera.cy_px};
  return true;
}

bool PixelToRay(const StereoCameraOptions& camera, const Eigen::Vector2d& uv_px,
                Eigen::Vector3d* ray_cam) {
  const Eigen::Vector2d xy_d((uv_px.x() - camera.cx_px) / camera.fx_px,
                             (uv_px.y() - camera.cy_px) / camera.fy_px);
  Eigen::Vector2d xy_u;
  if (!UndistortNormalized(camera, xy_d, &xy_u)) return false;
  // Beyond the turning point of the radial polynomial the inverse is not the
  // physical one; reject it.
  const double r2 = xy_u.squaredNorm();
  if (1.0 + 3.0 * camera.k1 * r2 + 5.0 * camera.k2 * r2 * r2 <= 0.0) return false;
  *ray_cam = Eigen::Vector3d(xy_u.x(), xy_u.y(), 1.0).normalized();
  return true;
}

calib::CameraModel CameraModelOf(const StereoCameraOptions& camera,
                                 const Eigen::Isometry3d& T_body_cam) {
  calib::CameraModel c;
  c.width_px = camera.width_px;
  c.height_px = camera.height_px;
  c.rate_hz = camera.rate_hz;
  c.intrinsics = {camera.fx_px, camera.fy_px, camera.cx_px, camera.cy_px};
  c.distortion = camera.DistortionCoeffs();
  c.T_body_cam = T_body_cam;
  // The renderer's cos^4 model is the calibration's.
  c.vignetting_cos4_strength = std::min(camera.vignetting_strength, 0.99);
  return c;
}

}  // namespace rover::sim
