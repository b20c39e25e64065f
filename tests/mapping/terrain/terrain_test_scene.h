#ifndef ROVER_TESTS_MAPPING_TERRAIN_TERRAIN_TEST_SCENE_H_
#define ROVER_TESTS_MAPPING_TERRAIN_TERRAIN_TEST_SCENE_H_

// Synthetic depth images for the terrain tests: a camera 1 m above ground,
// pitched down, looking along +x of a gravity frame (z up) at a heightfield
// h(x, y); each pixel's disparity is ray-marched exactly (no stereo noise),
// so the tests control what the classifiers see.

#include <cmath>
#include <functional>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "mapping/depth/depth_image.h"
#include "tests/mapping/mapping_test_head.h"

namespace rover::mapping::testing {

/// The simulator's head scaled down by `factor` (4: 188x120).
inline RectifiedStereo SmallHead(int factor = 4) { return SimulatorHead(factor); }

/// Camera at (0, 0, height) looking along +x, pitched down by `pitch_deg`.
inline Eigen::Isometry3d CameraPose(double height_m, double pitch_deg) {
  return CameraPose(0.0, 0.0, height_m, 0.0, pitch_deg);
}

/// The disparity image (CV_16S, 16 per px) of terrain `height(x, y)`, ray
/// marched to `max_range_m` (beyond: zero disparity, "infinitely far").
inline cv::Mat RenderDisparity(const RectifiedStereo& s, const Eigen::Isometry3d& T_gravity_cam,
                               const std::function<double(double, double)>& height,
                               double max_range_m = 40.0) {
  cv::Mat disparity(s.height_px, s.width_px, CV_16SC1, cv::Scalar(0));
  for (int v = 0; v < s.height_px; ++v) {
    for (int u = 0; u < s.width_px; ++u) {
      const Eigen::Vector3d ray_cam((u - s.cx_px) / s.focal_px, (v - s.cy_px) / s.focal_px, 1.0);
      const Eigen::Vector3d ray = T_gravity_cam.linear() * ray_cam;  // per unit of camera z
      const Eigen::Vector3d c = T_gravity_cam.translation();
      double hit_z = -1.0;
      double prev_t = 0.0;
      for (double t = 0.01; t < max_range_m; t += 0.01) {
        const Eigen::Vector3d p = c + t * ray;
        if (p.z() <= height(p.x(), p.y())) {
          hit_z = 0.5 * (t + prev_t);
          break;
        }
        prev_t = t;
      }
      if (hit_z > 0.0) {
        const double d = s.focal_px * s.baseline_m / hit_z;
        disparity.at<int16_t>(v, u) = static_cast<int16_t>(std::lround(16.0 * d));
      }
    }
  }
  return disparity;
}

}  // namespace rover::mapping::testing

#endif  // ROVER_TESTS_MAPPING_TERRAIN_TERRAIN_TEST_SCENE_H_
