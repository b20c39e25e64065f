#include "mapping/depth/depth_image.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace rover::mapping {

void DepthImageOptions::Validate() const {
  if (!(std::isfinite(min_disparity_px) && min_disparity_px > 0.0)) {
    throw std::invalid_argument("DepthImageOptions.min_disparity_px: expected > 0, found " +
                                std::to_string(min_disparity_px));
  }
  if (!(std::isfinite(max_depth_sigma_m) && max_depth_sigma_m > 0.0)) {
    throw std::invalid_argument("DepthImageOptions.max_depth_sigma_m: expected > 0, found " +
                                std::to_string(max_depth_sigma_m));
  }
}

DepthImage DepthImage::FromDisparity(const cv::Mat& disparity_q4, const StereoErrorModel& model,
                                     const DepthImageOptions& options) {
  options.Validate();
  const RectifiedStereo& s = model.stereo();
  if (disparity_q4.type() != CV_16SC1 || disparity_q4.cols != s.width_px ||
      disparity_q4.rows != s.height_px) {
    throw std::invalid_argument(
        "DepthImage: expected a CV_16S disparity of " + std::to_string(s.width_px) + "x" +
        std::to_string(s.height_px) + ", found type " + std::to_string(disparity_q4.type()) +
        " and " + std::to_string(disparity_q4.cols) + "x" + std::to_string(disparity_q4.rows));
  }
  DepthImage out;
  out.width_ = s.width_px;
  out.height_ = s.height_px;
  out.stereo_ = s;
  const std::size_t n =
      static_cast<std::size_t>(s.width_px) * static_cast<std::size_t>(s.height_px);
  out.states_.assign(n, DepthState::kInvalid);
  out.points_.assign(n, Eigen::Vector3f::Zero());
  out.depth_sigma_.assign(n, 0.0f);
  for (int v = 0; v < s.height_px; ++v) {
    const int16_t* row = disparity_q4.ptr<int16_t>(v);
    for (int u = 0; u < s.width_px; ++u) {
      const std::size_t i = out.Index(u, v);
      if (row[u] < 0) {
        ++out.counts_.invalid;
        continue;
      }
      const double d = row[u] / 16.0;
      if (d < options.min_disparity_px) {
        out.states_[i] = DepthState::kInfinite;
        ++out.counts_.infinite;
        continue;
      }
      const Eigen::Vector3d p = s.Triangulate(u, v, d);
      const double sigma_z = model.DepthSigma(p.z());
      out.points_[i] = p.cast<float>();
      out.depth_sigma_[i] = static_cast<float>(sigma_z);
      if (sigma_z > options.max_depth_sigma_m) {
        out.states_[i] = DepthState::kUncertain;
        ++out.counts_.uncertain;
      } else {
        out.states_[i] = DepthState::kValid;
        ++out.counts_.valid;
      }
    }
  }
  return out;
}

}  // namespace rover::mapping
