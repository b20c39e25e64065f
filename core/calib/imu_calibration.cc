#include "core/calib/imu_calibration.h"

#include <cmath>
#include <string>
#include <utility>

namespace rover::calib {

std::optional<FieldProblem> ImuCalibration::Problem() const {
  const std::pair<const char*, double> positive[] = {
      {"rate_hz", rate_hz},
      {"gyro_noise_density_rad_s_sqrt_hz", gyro_noise_density_rad_s_sqrt_hz},
      {"gyro_random_walk_rad_s2_sqrt_hz", gyro_random_walk_rad_s2_sqrt_hz},
      {"accel_noise_density_m_s2_sqrt_hz", accel_noise_density_m_s2_sqrt_hz},
      {"accel_random_walk_m_s3_sqrt_hz", accel_random_walk_m_s3_sqrt_hz},
  };
  for (const auto& [field, value] : positive) {
    if (!(value > 0.0) || !std::isfinite(value)) {
      return FieldProblem{field, "expected a finite number > 0, found " + NumberText(value)};
    }
  }
  if (std::optional<std::string> problem = RigidTransformProblem(T_body_imu.matrix())) {
    return FieldProblem{"T_body_imu", *problem};
  }
  return std::nullopt;
}

}  // namespace rover::calib
