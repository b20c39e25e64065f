#include "tests/mapping/tags/synthetic_tag_image.h"

#include <cmath>

#include "mapping/tags/tag_image_renderer.h"
#include "mapping/tags/tag_pattern.h"

namespace rover::mapping::testing {

calib::RectifiedIntrinsics TestCamera() {
  calib::RectifiedIntrinsics c;
  c.fx = c.fy = 376.0 / std::tan(M_PI / 6.0);
  c.cx = 375.5;
  c.cy = 239.5;
  return c;
}

Eigen::Isometry3d TagAt(double distance_m, double tilt_rad, double lateral_m) {
  // Head-on: tag z (into the tag) along camera z, tag x right, tag y down.
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(tilt_rad, Eigen::Vector3d::UnitY()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(lateral_m, 0.0, distance_m);
  return T;
}

cv::Mat RenderTag(int id, double tag_size_m, const Eigen::Isometry3d& T_camera_tag,
                  const calib::RectifiedIntrinsics& camera) {
  TagRenderOptions sharp;
  sharp.blur_sigma_px = 0.0;
  return RenderTagImage(MakeTagPattern("tag36h11", id), tag_size_m, T_camera_tag, camera,
                        cv::Size(752, 480), sharp);
}

}  // namespace rover::mapping::testing
