#include "mapping/depth/rectified_stereo.h"

#include <cmath>
#include <stdexcept>

namespace rover::mapping {

std::string RectifiedStereo::Problem() const {
  const auto positive = [](double v) { return std::isfinite(v) && v > 0.0; };
  if (width_px <= 0 || height_px <= 0) {
    return "image size: expected positive, found " + std::to_string(width_px) + "x" +
           std::to_string(height_px);
  }
  if (!positive(focal_px)) return "focal_px: expected > 0, found " + std::to_string(focal_px);
  if (!positive(baseline_m)) return "baseline_m: expected > 0, found " + std::to_string(baseline_m);
  if (!std::isfinite(cx_px) || !std::isfinite(cy_px)) return "principal point: expected finite";
  return {};
}

void RectifiedStereo::Validate() const {
  if (const std::string p = Problem(); !p.empty()) {
    throw std::invalid_argument("RectifiedStereo." + p);
  }
}

}  // namespace rover::mapping
