#include "mapping/slam/frame_switch_noise.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace rover::mapping {
namespace {

void RequireNonNegative(double value, const char* key) {
  if (!std::isfinite(value) || value < 0.0) {
    throw std::invalid_argument(std::string("frame switch noise: ") + key +
                                " must be finite and >= 0, got " + std::to_string(value));
  }
}

}  // namespace

void FrameSwitchNoiseOptions::Validate() const {
  if (!std::isfinite(filter_sigma_scale) || filter_sigma_scale <= 0.0) {
    throw std::invalid_argument(
        "frame switch noise: filter_sigma_scale must be finite and > 0, got " +
        std::to_string(filter_sigma_scale));
  }
  RequireNonNegative(along_sigma_per_m, "along_sigma_per_m");
  RequireNonNegative(across_sigma_per_m, "across_sigma_per_m");
  RequireNonNegative(yaw_sigma_rad_per_m, "yaw_sigma_rad_per_m");
}

FrameSwitchNoiseOptions FrameSwitchNoiseOptions::Load(const ConfigNode& node) {
  FrameSwitchNoiseOptions o;
  o.filter_sigma_scale = node.Get<double>("filter_sigma_scale", o.filter_sigma_scale);
  o.along_sigma_per_m = node.Get<double>("along_sigma_per_m", o.along_sigma_per_m);
  o.across_sigma_per_m = node.Get<double>("across_sigma_per_m", o.across_sigma_per_m);
  o.yaw_sigma_rad_per_m = node.Get<double>("yaw_sigma_rad_per_m", o.yaw_sigma_rad_per_m);
  o.Validate();
  return o;
}

Eigen::Matrix4d FrameSwitchCovariance(const Eigen::Matrix4d& filter_covariance,
                                      const Eigen::Vector3d& p_old_new_m,
                                      const FrameSwitchNoiseOptions& options) {
  Eigen::Matrix4d C = options.filter_sigma_scale * options.filter_sigma_scale * filter_covariance;
  const double d_m = p_old_new_m.norm();
  if (!(d_m > 0.0)) return C;
  const Eigen::Vector3d u = p_old_new_m / d_m;
  const Eigen::Matrix3d along = u * u.transpose();
  const double var_along = std::pow(options.along_sigma_per_m * d_m, 2);
  const double var_across = std::pow(options.across_sigma_per_m * d_m, 2);
  C.topLeftCorner<3, 3>() += var_along * along + var_across * (Eigen::Matrix3d::Identity() - along);
  C(3, 3) += std::pow(options.yaw_sigma_rad_per_m * d_m, 2);
  return C;
}

}  // namespace rover::mapping
