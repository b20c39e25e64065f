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
  return std::nullopt;
}

}  // namespace rover::calib
