#include "core/calib/camera_model.h"

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace rover::calib {
namespace {

// Newton steps for Unproject; both models converge quadratically from the
// distorted point, in 3-6 steps for real lenses.
constexpr int kMaxIterations = 30;
// Accepted residual of the inversion, in normalised image coordinates
// (1e-12 is ~1e-9 px for a 1000 px focal length).
constexpr double kTolerance = 1e-12;

// Radial-tangential distortion of the normalised point `p` and, if `J` is
// given, its Jacobian. The same formula as cv::projectPoints with four
// coefficients.
Eigen::Vector2d DistortRadTan(const std::array<double, 4>& d, const Eigen::Vector2d& p,
                              Eigen::Matrix2d* J) {
  const double k1 = d[0], k2 = d[1], p1 = d[2], p2 = d[3];
  const double x = p.x(), y = p.y();
  const double r2 = x * x + y * y;
  const double radial = 1.0 + k1 * r2 + k2 * r2 * r2;
  if (J != nullptr) {
    const double dradial_dr2 = k1 + 2.0 * k2 * r2;  // d radial / d x = 2 x dradial_dr2
    (*J)(0, 0) = radial + 2.0 * x * x * dradial_dr2 + 2.0 * p1 * y + 6.0 * p2 * x;
    (*J)(0, 1) = 2.0 * x * y * dradial_dr2 + 2.0 * p1 * x + 2.0 * p2 * y;
    (*J)(1, 0) = 2.0 * x * y * dradial_dr2 + 2.0 * p1 * x + 2.0 * p2 * y;
    (*J)(1, 1) = radial + 2.0 * y * y * dradial_dr2 + 6.0 * p1 * y + 2.0 * p2 * x;
  }
  return {x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x),
          y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y};
}

// theta_d of the equidistant model at angle `theta`, and its derivative.
double EquidistantThetaD(const std::array<double, 4>& k, double theta, double* derivative) {
  const double t2 = theta * theta;
  const double poly = 1.0 + t2 * (k[0] + t2 * (k[1] + t2 * (k[2] + t2 * k[3])));
  if (derivative != nullptr) {
    *derivative = 1.0 + t2 * (3.0 * k[0] + t2 * (5.0 * k[1] + t2 * (7.0 * k[2] + t2 * 9.0 * k[3])));
  }
  return theta * poly;
}

std::optional<Eigen::Vector2d> UndistortRadTan(const std::array<double, 4>& d,
                                               const Eigen::Vector2d& m) {
  Eigen::Vector2d p = m;
  Eigen::Matrix2d J;
  for (int i = 0; i < kMaxIterations; ++i) {
    const Eigen::Vector2d residual = DistortRadTan(d, p, &J) - m;
    if (residual.norm() <= kTolerance) {
      // A positive Jacobian keeps the solution on the branch the image uses,
      // inside the radius where the polynomial folds back.
      if (!(J.determinant() > 0.0)) return std::nullopt;
      return p;
    }
    if (!(std::abs(J.determinant()) > 0.0)) return std::nullopt;
    p -= J.inverse() * residual;
    if (!p.allFinite()) return std::nullopt;
  }
  return std::nullopt;
}

// The angle from the optical axis of a ray seen at normalised distorted
// radius `theta_d`, or nullopt past the fold or the half sphere.
std::optional<double> UndistortEquidistant(const std::array<double, 4>& k, double theta_d) {
  double theta = theta_d;
  for (int i = 0; i < kMaxIterations; ++i) {
    double slope = 0.0;
    const double residual = EquidistantThetaD(k, theta, &slope) - theta_d;
    if (std::abs(residual) <= kTolerance) {
      if (!(slope > 0.0) || !(theta >= 0.0) || !(theta < std::numbers::pi / 2)) {
        return std::nullopt;
      }
      return theta;
    }
    if (!(slope != 0.0)) return std::nullopt;
    theta -= residual / slope;
    if (!std::isfinite(theta)) return std::nullopt;
  }
  return std::nullopt;
}

}  // namespace

std::string_view EurocDistortionName(DistortionModel model) {
  switch (model) {
    case DistortionModel::kRadialTangential:
      return "radial-tangential";
    case DistortionModel::kEquidistant:
      return "equidistant";
  }
  return "unknown";
}

std::optional<Eigen::Vector2d> CameraModel::Project(const Eigen::Vector3d& p_cam) const {
  if (!(p_cam.z() > 0.0) || !p_cam.allFinite()) return std::nullopt;
  const Eigen::Vector2d p(p_cam.x() / p_cam.z(), p_cam.y() / p_cam.z());
  Eigen::Vector2d m;
  if (distortion_model == DistortionModel::kRadialTangential) {
    m = DistortRadTan(distortion, p, nullptr);
  } else {
    // As cv::fisheye::projectPoints: theta from the undistorted radius, and
    // no division by a radius that is (almost) zero.
    const double r = std::sqrt(p.dot(p));
    const double theta_d = EquidistantThetaD(distortion, std::atan(r), nullptr);
    m = r > 1e-8 ? Eigen::Vector2d(p * (theta_d / r)) : p;
  }
  return Eigen::Vector2d(intrinsics[0] * m.x() + intrinsics[2],
                         intrinsics[1] * m.y() + intrinsics[3]);
}

std::optional<Eigen::Vector3d> CameraModel::Unproject(const Eigen::Vector2d& pixel) const {
  if (!pixel.allFinite() || !(intrinsics[0] > 0.0) || !(intrinsics[1] > 0.0)) {
    return std::nullopt;
  }
  const Eigen::Vector2d m((pixel.x() - intrinsics[2]) / intrinsics[0],
                          (pixel.y() - intrinsics[3]) / intrinsics[1]);
  if (distortion_model == DistortionModel::kRadialTangential) {
    const std::optional<Eigen::Vector2d> p = UndistortRadTan(distortion, m);
    if (!p) return std::nullopt;
    return Eigen::Vector3d(p->x(), p->y(), 1.0).normalized();
  }
  const double theta_d = m.norm();
  if (theta_d == 0.0) return Eigen::Vector3d::UnitZ();
  const std::optional<double> theta = UndistortEquidistant(distortion, theta_d);
  if (!theta) return std::nullopt;
  const Eigen::Vector2d xy = m * (std::sin(*theta) / theta_d);
  return Eigen::Vector3d(xy.x(), xy.y(), std::cos(*theta));
}

std::optional<FieldProblem> CameraModel::Problem() const {
  if (width_px <= 0) {
    return FieldProblem{"width_px", "expected > 0 px, found " + std::to_string(width_px)};
  }
  if (height_px <= 0) {
    return FieldProblem{"height_px", "expected > 0 px, found " + std::to_string(height_px)};
  }
  if (!(rate_hz > 0.0) || !std::isfinite(rate_hz)) {
    return FieldProblem{"rate_hz", "expected a frame rate > 0 Hz, found " + NumberText(rate_hz)};
  }
  for (const double v : intrinsics) {
    if (!std::isfinite(v)) {
      return FieldProblem{"intrinsics", "expected finite fu, fv, cu, cv, found " + NumberText(v)};
    }
  }
  if (!(intrinsics[0] > 0.0) || !(intrinsics[1] > 0.0)) {
    return FieldProblem{"intrinsics", "expected focal lengths fu, fv > 0 px, found fu = " +
                                          NumberText(intrinsics[0]) +
                                          ", fv = " + NumberText(intrinsics[1])};
  }
  for (const double v : distortion) {
    if (!std::isfinite(v)) {
      return FieldProblem{"distortion", "expected finite coefficients, found " + NumberText(v)};
    }
  }
  if (std::optional<std::string> problem = RigidTransformProblem(T_body_cam.matrix())) {
    return FieldProblem{"T_body_cam", *problem};
  }
  if (!(vignetting_cos4_strength >= 0.0 && vignetting_cos4_strength < 1.0)) {
    return FieldProblem{"vignetting_cos4_strength", "expected a strength in [0, 1), found " +
                                                        NumberText(vignetting_cos4_strength)};
  }
  return std::nullopt;
}

void CameraModel::Validate() const {
  if (const std::optional<FieldProblem> problem = Problem()) {
    throw std::invalid_argument(problem->field + ": " + problem->message);
  }
}

bool operator==(const CameraModel& a, const CameraModel& b) {
  return a.width_px == b.width_px && a.height_px == b.height_px && a.rate_hz == b.rate_hz &&
         a.distortion_model == b.distortion_model && a.intrinsics == b.intrinsics &&
         a.distortion == b.distortion && a.T_body_cam.matrix() == b.T_body_cam.matrix() &&
         a.vignetting_cos4_strength == b.vignetting_cos4_strength;
}

}  // namespace rover::calib
