// mapd's per-image pipeline (LocalMapper) on analytically rendered pairs
// taken through vignetting lenses: the rectifier's flat field brightens the
// corners, sensor noise included, and the disparity's texture filter must
// still tell the sky's noise from texture there.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include <opencv2/core.hpp>

#include "firmware/mapd/local_mapper.h"
#include "mapping/submap/submap.h"
#include "tests/firmware/mapd/stereo_scene.h"

namespace rover::mapd {
namespace {

constexpr double kVignetting = 0.5;  // the simulator's lens (cos^4 strength)
constexpr double kSkyDn = 45.0;      // the simulator's sky at the image centre
constexpr double kNoiseDn = 1.5;     // read and shot noise, one sigma

calib::CameraModel VignettedCamera(const testing::StereoScene& scene, int index) {
  calib::CameraModel c = scene.Camera(index);
  c.vignetting_cos4_strength = kVignetting;
  return c;
}

// fx, fy, cx, cy in CameraModel::intrinsics.
// What the sensor records of `scene_dn` (the scene as a flat-field lens would
// show it): darkened by cos^4 towards the corners, plus seeded Gaussian
// noise, rounded to 8 bits.
cv::Mat Capture(const calib::CameraModel& cam, const std::vector<uint8_t>& scene_dn,
                std::mt19937* rng) {
  std::normal_distribution<double> noise(0.0, kNoiseDn);
  cv::Mat raw(cam.height_px, cam.width_px, CV_8UC1);
  for (int v = 0; v < cam.height_px; ++v) {
    for (int u = 0; u < cam.width_px; ++u) {
      const double x = (u + 0.5 - cam.intrinsics[2]) / cam.intrinsics[0];
      const double y = (v + 0.5 - cam.intrinsics[3]) / cam.intrinsics[1];
      const double cos2 = 1.0 / (1.0 + x * x + y * y);
      const double brightness = 1.0 - kVignetting * (1.0 - cos2 * cos2);
      const double dn =
          scene_dn[static_cast<std::size_t>(v * cam.width_px + u)] * brightness + noise(*rng);
      raw.at<uint8_t>(v, u) = static_cast<uint8_t>(std::clamp(std::round(dn), 0.0, 255.0));
    }
  }
  return raw;
}

TEST(LocalMapperTest, TheSkysNoiseGetsNoDepthWhereTheFlatFieldBrightensIt) {
  const testing::StereoScene scene;
  const calib::CameraModel cam0 = VignettedCamera(scene, 0);
  const calib::CameraModel cam1 = VignettedCamera(scene, 1);
  LocalMapper mapper({}, cam0, cam1);
  const std::vector<uint8_t> sky(static_cast<std::size_t>(scene.width_px * scene.height_px),
                                 static_cast<uint8_t>(kSkyDn));
  std::mt19937 rng(7);
  mapping::Submap submap(0, 0, {});
  int valid = 0;
  int flagged = 0;
  for (int i = 0; i < 4; ++i) {
    // Independent noise in the two cameras: nothing there to match.
    const MappedImage out = mapper.Process(Capture(cam0, sky, &rng), Capture(cam1, sky, &rng),
                                           Eigen::Isometry3d::Identity(), &submap);
    valid += out.depth.valid + out.depth.uncertain;
    flagged += out.obstacle_points;
  }
  EXPECT_EQ(valid, 0);
  EXPECT_EQ(flagged, 0);
}

TEST(LocalMapperTest, TheGroundKeepsItsDepthWhereTheFlatFieldBrightensIt) {
  const testing::StereoScene scene;
  const calib::CameraModel cam0 = VignettedCamera(scene, 0);
  const calib::CameraModel cam1 = VignettedCamera(scene, 1);
  LocalMapper mapper({}, cam0, cam1);
  const auto render = [&scene](int index) {
    std::vector<uint8_t> image(static_cast<std::size_t>(scene.width_px * scene.height_px));
    scene.Render(index, Eigen::Isometry3d::Identity(), image.data());
    return image;
  };
  std::mt19937 rng(11);
  mapping::Submap submap(0, 0, {});
  mapper.Process(Capture(cam0, render(0), &rng), Capture(cam1, render(1), &rng),
                 Eigen::Isometry3d::Identity(), &submap);
  // The lower right corner (ground at about 1 m) is where the gain is
  // highest, and SGBM searches its full range (the left image's left edge
  // has no match in the right one).
  const mapping::DepthImage& depth = *mapper.last_depth();
  const int w = depth.width();
  const int h = depth.height();
  const int side = w / 6;
  int corner = 0;
  int corner_valid = 0;
  for (int v = h - side; v < h - 8; ++v) {
    for (int u = w - side; u < w - 8; ++u) {
      ++corner;
      if (depth.state(u, v) == mapping::DepthState::kValid) ++corner_valid;
    }
  }
  // 0.80 from one SGBM pass; the flipped second pass (DisparityOptions::
  // flip_pass) drops the pixels where the two passes disagree: 0.79.
  EXPECT_GT(static_cast<double>(corner_valid) / corner, 0.75);
}

}  // namespace
}  // namespace rover::mapd
