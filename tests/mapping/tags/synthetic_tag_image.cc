#include "tests/mapping/tags/synthetic_tag_image.h"

#include <cmath>

#include <opencv2/imgproc.hpp>

#include "hil/sim/render/apriltag_pattern.h"

namespace rover::mapping::testing {

calib::RectifiedIntrinsics TestCamera() {
  calib::RectifiedIntrinsics c;
  c.fx = c.fy = 376.0 / std::tan(M_PI / 6.0);
  c.cx = 375.5;
  c.cy = 239.5;
  return c;
}

Eigen::Isometry3d TagAt(double distance_m, double tilt_rad, double lateral_m) {
  // Facing the camera head-on: tag z (into the tag) along camera z, tag x
  // right, tag y down.
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(tilt_rad, Eigen::Vector3d::UnitY()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(lateral_m, 0.0, distance_m);
  return T;
}

cv::Mat RenderTag(int id, double tag_size_m, const Eigen::Isometry3d& T_camera_tag,
                  const calib::RectifiedIntrinsics& camera, int width, int height) {
  const sim::TagPattern pattern = sim::Tag36h11Pattern(id);
  constexpr int kPxPerCell = 32;
  const int n = pattern.cells_per_side;
  cv::Mat printed(n * kPxPerCell, n * kPxPerCell, CV_8UC1);
  for (int r = 0; r < printed.rows; ++r) {
    for (int c = 0; c < printed.cols; ++c) {
      printed.at<uint8_t>(r, c) =
          pattern.cells[static_cast<std::size_t>((r / kPxPerCell) * n + c / kPxPerCell)] ? 230 : 20;
    }
  }
  // Printed pixel centre (u, v) -> tag plane (x, y): the black square of
  // border_cells spans the tag size, centred on the pattern.
  const double cell_m = tag_size_m / pattern.border_cells;
  Eigen::Matrix3d A = Eigen::Matrix3d::Identity();
  A(0, 0) = A(1, 1) = cell_m / kPxPerCell;
  A(0, 2) = A(1, 2) = (0.5 / kPxPerCell - n / 2.0) * cell_m;
  Eigen::Matrix3d K = Eigen::Matrix3d::Identity();
  K(0, 0) = camera.fx;
  K(1, 1) = camera.fy;
  K(0, 2) = camera.cx;
  K(1, 2) = camera.cy;
  Eigen::Matrix3d P;
  P.col(0) = T_camera_tag.linear().col(0);
  P.col(1) = T_camera_tag.linear().col(1);
  P.col(2) = T_camera_tag.translation();
  // Supersampled: image pixel x = (X + 0.5) / f - 0.5 for a fine pixel X.
  constexpr double f = 4.0;
  Eigen::Matrix3d S = Eigen::Matrix3d::Identity();
  S(0, 0) = S(1, 1) = f;
  S(0, 2) = S(1, 2) = 0.5 * f - 0.5;
  const Eigen::Matrix3d H = S * K * P * A;
  cv::Matx33d H_cv;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) H_cv(r, c) = H(r, c);
  }
  cv::Mat fine;
  cv::warpPerspective(printed, fine, H_cv, cv::Size(width * 4, height * 4), cv::INTER_LINEAR,
                      cv::BORDER_CONSTANT, cv::Scalar(128));
  cv::Mat image;
  cv::resize(fine, image, cv::Size(width, height), 0, 0, cv::INTER_AREA);
  return image;
}

}  // namespace rover::mapping::testing
