#include "mapping/tags/tag_image_renderer.h"

#include <cmath>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

#include "mapping/loop/option_checks.h"

namespace rover::mapping {
namespace {

using loop_internal::CheckRange;

// Printed pixels per cell of the pattern image that is warped.
constexpr int kPrintedPxPerCell = 32;

cv::Mat PrintedPattern(const TagPattern& pattern, uint8_t black, uint8_t white) {
  const int n = pattern.cells_per_side;
  cv::Mat printed(n * kPrintedPxPerCell, n * kPrintedPxPerCell, CV_8UC1);
  for (int r = 0; r < printed.rows; ++r) {
    for (int c = 0; c < printed.cols; ++c) {
      const std::size_t cell =
          static_cast<std::size_t>((r / kPrintedPxPerCell) * n + c / kPrintedPxPerCell);
      printed.at<uint8_t>(r, c) = pattern.cells[cell] ? white : black;
    }
  }
  return printed;
}

}  // namespace

void TagRenderOptions::Validate() const {
  constexpr const char* kName = "TagRenderOptions";
  CheckRange(kName, "supersampling", supersampling, 1, 16);
  CheckRange(kName, "blur_sigma_px", blur_sigma_px, 0.0, 20.0);
  CheckRange(kName, "noise_sigma_dn", noise_sigma_dn, 0.0, 100.0);
  if (white_dn <= black_dn) {
    loop_internal::FailOption(kName, "white_dn", "above black_dn", white_dn);
  }
}

cv::Mat RenderTagImage(const TagPattern& pattern, double tag_size_m,
                       const Eigen::Isometry3d& T_camera_tag,
                       const calib::RectifiedIntrinsics& camera, cv::Size size,
                       const TagRenderOptions& options) {
  options.Validate();
  if (!(tag_size_m > 0.0) || size.width <= 0 || size.height <= 0 || pattern.cells.empty()) {
    throw std::invalid_argument(
        "RenderTagImage: expected a tag size > 0 m, a pattern and a "
        "non-empty image size");
  }
  if (!(T_camera_tag.translation().z() > 0.0)) {
    throw std::invalid_argument("RenderTagImage: the tag centre is not in front of the camera");
  }
  // Printed pixel centre (u, v) -> tag plane (x, y): the black square of
  // border_cells spans the tag size, centred on the pattern.
  const double cell_m = tag_size_m / pattern.border_cells;
  Eigen::Matrix3d A = Eigen::Matrix3d::Identity();
  A(0, 0) = A(1, 1) = cell_m / kPrintedPxPerCell;
  A(0, 2) = A(1, 2) = (0.5 / kPrintedPxPerCell - pattern.cells_per_side / 2.0) * cell_m;
  Eigen::Matrix3d K = Eigen::Matrix3d::Identity();
  K(0, 0) = camera.fx;
  K(1, 1) = camera.fy;
  K(0, 2) = camera.cx;
  K(1, 2) = camera.cy;
  Eigen::Matrix3d P;  // plane (x, y, 1) -> image, for z = 0 on the tag
  P.col(0) = T_camera_tag.linear().col(0);
  P.col(1) = T_camera_tag.linear().col(1);
  P.col(2) = T_camera_tag.translation();
  // Fine pixel X covers image x = (X + 0.5) / f - 0.5.
  const double f = options.supersampling;
  Eigen::Matrix3d S = Eigen::Matrix3d::Identity();
  S(0, 0) = S(1, 1) = f;
  S(0, 2) = S(1, 2) = 0.5 * f - 0.5;
  const Eigen::Matrix3d H = S * K * P * A;
  cv::Matx33d H_cv;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) H_cv(r, c) = H(r, c);
  }
  cv::Mat fine;
  cv::warpPerspective(
      PrintedPattern(pattern, options.black_dn, options.white_dn), fine, H_cv,
      cv::Size(size.width * options.supersampling, size.height * options.supersampling),
      cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(options.background_dn));
  cv::Mat image;
  cv::resize(fine, image, size, 0, 0, cv::INTER_AREA);
  if (options.blur_sigma_px > 0.0) {
    cv::GaussianBlur(image, image, cv::Size(), options.blur_sigma_px);
  }
  if (options.noise_sigma_dn > 0.0) {
    cv::Mat noise(size, CV_32F);
    cv::RNG rng(options.noise_seed);
    rng.fill(noise, cv::RNG::NORMAL, 0.0, options.noise_sigma_dn);
    cv::Mat sum;
    image.convertTo(sum, CV_32F);
    sum += noise;
    sum.convertTo(image, CV_8U);  // saturates
  }
  return image;
}

}  // namespace rover::mapping
