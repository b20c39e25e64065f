#include "core/calib/wheel_calibration.h"

#include <cmath>

namespace rover::calib {

std::optional<FieldProblem> WheelCalibration::Problem() const {
  if (!(wheel_radius_m > 0.0) || !std::isfinite(wheel_radius_m)) {
    return FieldProblem{"wheel_radius_m",
                        "expected a finite radius > 0 m, found " + NumberText(wheel_radius_m)};
  }
  if (!(track_m > 0.0) || !std::isfinite(track_m)) {
    return FieldProblem{"track_m", "expected a finite track > 0 m, found " + NumberText(track_m)};
  }
  if (!lever_arm_body_m.allFinite()) {
    return FieldProblem{"lever_arm_body_m", "expected finite x, y, z, found a NaN or an infinity"};
  }
  if (!nonholonomic_point_body_m.allFinite()) {
    return FieldProblem{"nonholonomic_point_body_m",
                        "expected finite x, y, z, found a NaN or an infinity"};
  }
  if (!(yaw_scrub_factor > 0.0) || !std::isfinite(yaw_scrub_factor)) {
    return FieldProblem{"yaw_scrub_factor",
                        "expected a finite factor > 0, found " + NumberText(yaw_scrub_factor)};
  }
  if (!std::isfinite(slip_ratio_base)) {
    return FieldProblem{"slip_ratio_base",
                        "expected a finite ratio, found " + NumberText(slip_ratio_base)};
  }
  if (!std::isfinite(slip_ratio_per_tilt_rad)) {
    return FieldProblem{"slip_ratio_per_tilt_rad", "expected a finite ratio per radian, found " +
                                                       NumberText(slip_ratio_per_tilt_rad)};
  }
  return std::nullopt;
}

WheelCalibration WheelCalibration::Load(const ConfigNode& node) {
  WheelCalibration c;
  c.wheel_radius_m = node.Get<double>("wheel_radius_m");
  c.track_m = node.Get<double>("track_m");
  c.lever_arm_body_m = node.Get<Eigen::Vector3d>("lever_arm_body_m");
  // Without a stated point, the contact centre under the wheel centres.
  c.nonholonomic_point_body_m =
      node.Get<Eigen::Vector3d>("nonholonomic_point_body_m",
                                c.lever_arm_body_m - Eigen::Vector3d(0.0, 0.0, c.wheel_radius_m));
  c.yaw_scrub_factor = node.Get<double>("yaw_scrub_factor", c.yaw_scrub_factor);
  c.slip_ratio_base = node.Get<double>("slip_ratio_base", c.slip_ratio_base);
  c.slip_ratio_per_tilt_rad =
      node.Get<double>("slip_ratio_per_tilt_rad", c.slip_ratio_per_tilt_rad);
  if (const std::optional<FieldProblem> problem = c.Problem()) {
    node.Fail(problem->field, problem->message);
  }
  return c;
}

std::string WheelCalibration::ToYaml(int indent) const {
  const std::string pad(static_cast<std::size_t>(indent), ' ');
  const auto vec = [](const Eigen::Vector3d& v) {
    return "[" + NumberText(v.x()) + ", " + NumberText(v.y()) + ", " + NumberText(v.z()) + "]";
  };
  return pad + "wheel_radius_m: " + NumberText(wheel_radius_m) + "\n" + pad +
         "track_m: " + NumberText(track_m) + "\n" + pad +
         "lever_arm_body_m: " + vec(lever_arm_body_m) + "\n" + pad +
         "nonholonomic_point_body_m: " + vec(nonholonomic_point_body_m) + "\n" + pad +
         "yaw_scrub_factor: " + NumberText(yaw_scrub_factor) + "\n" + pad +
         "slip_ratio_base: " + NumberText(slip_ratio_base) + "\n" + pad +
         "slip_ratio_per_tilt_rad: " + NumberText(slip_ratio_per_tilt_rad) + "\n";
}

}  // namespace rover::calib
