#include "mapping/slam/frame_switch_noise.h"

#include <cmath>
#include <limits>

#include "mapping/loop/option_checks.h"

namespace rover::mapping {

void FrameSwitchNoiseOptions::Validate() const {
  constexpr const char* kC = "FrameSwitchNoiseOptions";
  constexpr double kInf = std::numeric_limits<double>::infinity();
  loop_internal::CheckPositive(kC, "filter_sigma_scale", filter_sigma_scale);
  loop_internal::CheckRange(kC, "along_sigma_per_m", along_sigma_per_m, 0.0, kInf);
  loop_internal::CheckRange(kC, "across_sigma_per_m", across_sigma_per_m, 0.0, kInf);
  loop_internal::CheckRange(kC, "yaw_sigma_rad_per_m", yaw_sigma_rad_per_m, 0.0, kInf);
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
