// End-to-end checks of the stereo renderer on small synthetic worlds:
//  1. depth-buffer depth against ray-cast terrain geometry (1 cm at 5 m);
//  2. OpenCV SGBM on the rectified pair against ground-truth disparity, which
//     proves the calibration the renderer reports is the one it renders with;
//  3. apriltag detection of rendered tags at 3 m, corners against projected
//     ground truth;
//  4. byte-identical output for identical inputs.

#include <apriltag/apriltag.h>
#include <apriltag/tag36h11.h>
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/core/eigen.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <vector>

#include "hil/sim/render/stereo_camera.h"
#include "hil/sim/render/stereo_renderer.h"
#include "tests/hil/sim/render/tag_detection.h"
#include "tests/hil/sim/render/test_world.h"

namespace rover::sim {
namespace {

using testing::MakeTestWorld;
using testing::TestWorldOptions;

// Body frame at wheel-axle height (0.15 m) above the terrain at (x, y), yawed.
Eigen::Isometry3d BodyPose(const World& world, double x_m, double y_m, double yaw_rad) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(x_m, y_m, world.terrain.HeightAt(x_m, y_m) + 0.15);
  return T;
}

bool SameBytes(const cv::Mat& a, const cv::Mat& b) {
  if (a.size() != b.size() || a.type() != b.type() || !a.isContinuous() || !b.isContinuous()) {
    return false;
  }
  return std::memcmp(a.data, b.data, a.total() * a.elemSize()) == 0;
}

// The renderer is the expensive part to set up; the terrain-only tests share one.
class TerrainRenderTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    world_ = new World(MakeTestWorld(TestWorldOptions()));
    renderer_ = new StereoRenderer(*world_, StereoCameraOptions());
    std::printf("GL renderer: %s, render size %d x %d per camera\n",
                renderer_->gl_renderer().c_str(), renderer_->render_width_px(),
                renderer_->render_height_px());
  }
  static void TearDownTestSuite() {
    delete renderer_;
    delete world_;
    renderer_ = nullptr;
    world_ = nullptr;
  }
  static World* world_;
  static StereoRenderer* renderer_;
};

World* TerrainRenderTest::world_ = nullptr;
StereoRenderer* TerrainRenderTest::renderer_ = nullptr;

TEST_F(TerrainRenderTest, RunsOnLlvmpipe) {
  EXPECT_NE(renderer_->gl_renderer().find("llvmpipe"), std::string::npos)
      << renderer_->gl_renderer();
}

TEST_F(TerrainRenderTest, DepthMatchesRaycastWithinOneCentimetreAtFiveMetres) {
  const StereoCameraOptions& camera = renderer_->camera();
  const Eigen::Isometry3d T_world_body = BodyPose(*world_, 0.4, -0.3, 0.35);
  RenderedStereoFrame frame;
  renderer_->Render(T_world_body, {}, 0, &frame);
  ASSERT_EQ(frame.depth0_m.type(), CV_32FC1);
  ASSERT_EQ(frame.depth0_m.cols, camera.width_px);
  ASSERT_EQ(frame.depth0_m.rows, camera.height_px);

  const Eigen::Isometry3d T_world_cam0 = T_world_body * camera.T_body_cam0;
  // Ray-cast z-depth of the (distorted) pixel (u, v); NaN if nothing is hit.
  // Also gives the range along the ray and the sine of the angle between the
  // ray and the surface.
  auto raycast_depth = [&](double u, double v, double* range = nullptr,
                           double* sin_grazing = nullptr) {
    Eigen::Vector3d ray_cam;
    if (!PixelToRay(camera, Eigen::Vector2d(u, v), &ray_cam)) return std::nan("");
    const Eigen::Vector3d ray_world = T_world_cam0.linear() * ray_cam;
    double range_m = 0.0;
    if (!world_->terrain.Raycast(T_world_cam0.translation(), ray_world, 100.0, &range_m)) {
      return std::nan("");
    }
    if (range != nullptr) *range = range_m;
    if (sin_grazing != nullptr) {
      const Eigen::Vector3d hit = T_world_cam0.translation() + range_m * ray_world;
      *sin_grazing = std::abs(ray_world.dot(world_->terrain.NormalAt(hit.x(), hit.y())));
    }
    return range_m * ray_cam.z();
  };

  std::mt19937_64 rng(11);
  std::uniform_int_distribution<int> pick_u(1, camera.width_px - 2);
  std::uniform_int_distribution<int> pick_v(1, camera.height_px - 2);
  // "At 5 m" is the distance along the ray. The renderer's mesh is the full
  // heightfield within full_resolution_distance_m (6 m); beyond it, it is
  // only as fine as the image needs, so it is compared within 6 m only.
  const double full_resolution_m = renderer_->options().full_resolution_distance_m;
  int checked_5m = 0;
  double max_error_5m = 0.0;
  int checked_all = 0;
  double max_relative_all = 0.0;
  int grazing = 0;
  int boundary = 0;
  for (int i = 0; i < 30000 && checked_5m < 400; ++i) {
    const int u = pick_u(rng);
    const int v = pick_v(rng);
    double sin_grazing = 0.0;
    double range_m = 0.0;
    const double expected = raycast_depth(u, v, &range_m, &sin_grazing);
    if (!std::isfinite(expected) || range_m > full_resolution_m - 0.1) continue;
    // Skip occlusion boundaries, where a pixel has no single depth, and rays
    // that only graze the surface (silhouettes of crests), where a height
    // difference of 0.1 mm between the triangle mesh and the bilinear surface
    // moves the hit by centimetres.
    if (sin_grazing < std::sin(3.0 * M_PI / 180.0)) {
      ++grazing;
      continue;
    }
    // A boundary within a pixel of (u, v) bends the depth profile: its
    // second difference is far above the smooth-terrain one (~1e-3 * z).
    bool smooth = true;
    for (const auto& [du, dv] : {std::pair{1, 0}, {0, 1}}) {
      const double before = raycast_depth(u - du, v - dv);
      const double after = raycast_depth(u + du, v + dv);
      smooth = smooth && std::isfinite(before) && std::isfinite(after) &&
               std::abs(before + after - 2.0 * expected) < 5e-3 * expected;
    }
    if (!smooth) {
      ++boundary;
      continue;
    }
    const double rendered = frame.depth0_m.at<float>(v, u);
    ASSERT_GT(rendered, 0.0) << "no depth at (" << u << ", " << v << ")";
    const double error = std::abs(rendered - expected);
    ++checked_all;
    max_relative_all = std::max(max_relative_all, error / expected);
    if (range_m >= 4.5 && range_m <= 5.5) {
      ++checked_5m;
      max_error_5m = std::max(max_error_5m, error);
      EXPECT_LT(error, 0.01) << "pixel (" << u << ", " << v << "): rendered " << rendered
                             << " m, ray cast " << expected << " m";
    }
  }
  std::printf(
      "depth check: %d pixels at 4.5-5.5 m, max error %.2f mm; %d pixels within %.1f m, "
      "max relative error %.2e; skipped %d grazing, %d at occlusion boundaries\n",
      checked_5m, 1e3 * max_error_5m, checked_all, full_resolution_m, max_relative_all, grazing,
      boundary);
  EXPECT_GE(checked_5m, 100);
  EXPECT_LT(max_relative_all, 2e-3);

  // The sky (looking up at the horizon) is invalid: 0.
  int invalid = 0;
  for (int u = 0; u < camera.width_px; ++u) invalid += frame.depth0_m.at<float>(0, u) == 0.0f;
  std::printf("top row: %d of %d pixels without depth\n", invalid, camera.width_px);
}

TEST_F(TerrainRenderTest, SgbmOnRectifiedPairMatchesGroundTruthDisparity) {
  const StereoCameraOptions& camera = renderer_->camera();
  RenderedStereoFrame frame;
  renderer_->Render(BodyPose(*world_, -1.0, 2.0, -0.6), {}, 3, &frame);

  // Rectify with the calibration as sensor.yaml states it.
  cv::Mat K;
  cv::eigen2cv(camera.CameraMatrix(), K);
  const std::array<double, 4> d = camera.DistortionCoeffs();
  const cv::Mat D = (cv::Mat_<double>(1, 4) << d[0], d[1], d[2], d[3]);
  // OpenCV's R, T map cam0 coordinates into cam1: x1 = R x0 + T.
  const Eigen::Isometry3d T_cam1_cam0 = camera.T_cam0_cam1().inverse();
  cv::Mat R;
  cv::Mat T;
  cv::eigen2cv(Eigen::Matrix3d(T_cam1_cam0.linear()), R);
  cv::eigen2cv(Eigen::Vector3d(T_cam1_cam0.translation()), T);
  const cv::Size size(camera.width_px, camera.height_px);
  cv::Mat R1, R2, P1, P2, Q;
  cv::stereoRectify(K, D, K, D, size, R, T, R1, R2, P1, P2, Q, cv::CALIB_ZERO_DISPARITY, 0.0);
  cv::Mat map0x, map0y, map1x, map1y;
  cv::initUndistortRectifyMap(K, D, R1, P1, size, CV_32FC1, map0x, map0y);
  cv::initUndistortRectifyMap(K, D, R2, P2, size, CV_32FC1, map1x, map1y);
  cv::Mat left, right, depth_rect;
  cv::remap(frame.cam0, left, map0x, map0y, cv::INTER_LINEAR);
  cv::remap(frame.cam1, right, map1x, map1y, cv::INTER_LINEAR);
  cv::remap(frame.depth0_m, depth_rect, map0x, map0y, cv::INTER_NEAREST, cv::BORDER_CONSTANT,
            cv::Scalar(0));

  constexpr int kDisparities = 96;
  constexpr int kBlock = 5;
  const cv::Ptr<cv::StereoSGBM> sgbm =
      cv::StereoSGBM::create(0, kDisparities, kBlock, 8 * kBlock * kBlock, 32 * kBlock * kBlock, 1,
                             0, 10, 100, 2, cv::StereoSGBM::MODE_SGBM);
  cv::Mat disparity16;
  sgbm->compute(left, right, disparity16);

  // Ground-truth disparity: z-depth in the rectified frame from cam0's
  // z-depth (R1 rotates cam0 into it), then f * b / z.
  const double f_rect = P1.at<double>(0, 0);
  const double baseline_f = -P2.at<double>(0, 3);
  Eigen::Matrix3d R1e;
  cv::cv2eigen(R1, R1e);
  cv::Mat gx, gy, gradient;
  cv::Sobel(left, gx, CV_32F, 1, 0);
  cv::Sobel(left, gy, CV_32F, 0, 1);
  cv::magnitude(gx, gy, gradient);
  cv::blur(gradient, gradient, cv::Size(kBlock, kBlock));

  int textured = 0;
  int matched = 0;
  int low_texture = 0;
  for (int v = kBlock; v < size.height - kBlock; ++v) {
    for (int u = kDisparities + kBlock; u < size.width - kBlock; ++u) {
      const double z_cam0 = depth_rect.at<float>(v, u);
      if (!(z_cam0 > 0.0)) continue;
      const Eigen::Vector3d ray_rect((u - P1.at<double>(0, 2)) / f_rect,
                                     (v - P1.at<double>(1, 2)) / P1.at<double>(1, 1), 1.0);
      const double z_rect = z_cam0 / (R1e.transpose() * ray_rect).z();
      const double expected = baseline_f / z_rect;
      if (expected < 1.0 || expected > kDisparities - 2) continue;
      // Textured: mean Sobel gradient magnitude over the block (in DN per
      // pixel, Sobel scale 8) above a few DN.
      if (gradient.at<float>(v, u) < 16.0f) {
        ++low_texture;
        continue;
      }
      ++textured;
      const int16_t raw = disparity16.at<int16_t>(v, u);
      if (raw >= 0 && std::abs(raw / 16.0 - expected) <= 1.0) ++matched;
    }
  }
  const double fraction = static_cast<double>(matched) / std::max(textured, 1);
  std::printf("SGBM: %d textured pixels (%d low-texture skipped), %.1f %% within 1 px\n", textured,
              low_texture, 100.0 * fraction);
  EXPECT_GT(textured, size.area() / 3);
  EXPECT_GE(fraction, 0.90);
}

TEST_F(TerrainRenderTest, IdenticalInputsGiveIdenticalBytes) {
  const Eigen::Isometry3d T_world_body = BodyPose(*world_, 2.0, 1.0, 1.2);
  RenderedStereoFrame a;
  RenderedStereoFrame b;
  RenderedStereoFrame c;
  renderer_->Render(T_world_body, {}, 17, &a);
  renderer_->Render(BodyPose(*world_, -3.0, 0.0, 0.0), {}, 16, &c);  // something in between
  renderer_->Render(T_world_body, {}, 17, &b);
  EXPECT_TRUE(SameBytes(a.cam0, b.cam0));
  EXPECT_TRUE(SameBytes(a.cam1, b.cam1));
  EXPECT_TRUE(SameBytes(a.depth0_m, b.depth0_m));

  // Another frame index draws other noise over the same scene.
  renderer_->Render(T_world_body, {}, 18, &c);
  EXPECT_FALSE(SameBytes(a.cam0, c.cam0));
  EXPECT_TRUE(SameBytes(a.depth0_m, c.depth0_m));

  // A second renderer (its own GL context) gives the same bytes.
  StereoRenderer other(*world_, StereoCameraOptions());
  RenderedStereoFrame d;
  other.Render(T_world_body, {}, 17, &d);
  EXPECT_TRUE(SameBytes(a.cam0, d.cam0));
  EXPECT_TRUE(SameBytes(a.cam1, d.cam1));
  EXPECT_TRUE(SameBytes(a.depth0_m, d.depth0_m));
}

TEST_F(TerrainRenderTest, ExposureAndGainScaleTheImage) {
  const Eigen::Isometry3d T_world_body = BodyPose(*world_, 0.0, 0.0, 0.0);
  StereoCameraOptions bright = renderer_->camera();
  bright.exposure_time_s *= 2.0;
  RenderOptions clean;
  clean.apply_effects = false;
  StereoRenderer base_renderer(*world_, renderer_->camera(), clean);
  StereoRenderer bright_renderer(*world_, bright, clean);
  RenderedStereoFrame base;
  RenderedStereoFrame doubled;
  base_renderer.Render(T_world_body, {}, 0, &base);
  bright_renderer.Render(T_world_body, {}, 0, &doubled);
  // Unsaturated pixels double (within rounding).
  int compared = 0;
  for (int v = 0; v < base.cam0.rows; v += 7) {
    for (int u = 0; u < base.cam0.cols; u += 7) {
      const int a = base.cam0.at<uint8_t>(v, u);
      const int b = doubled.cam0.at<uint8_t>(v, u);
      if (a < 10 || b >= 255) continue;
      ++compared;
      EXPECT_NEAR(b, 2 * a, 2) << "(" << u << ", " << v << ")";
    }
  }
  EXPECT_GT(compared, 1000);
}

TEST(TerrainLodRenderTest, NoCracksBetweenPatchesOfDifferentLevels) {
  // Rough ground (seeded +-5 cm noise per sample) and an extreme level-of-
  // detail setting, so that patches of many levels meet right in front of
  // the camera. A crack between them would show the sky: no depth.
  TestWorldOptions world_options;
  world_options.amplitude_m = 0.0;
  World world = MakeTestWorld(world_options);
  std::vector<float> heights = world.terrain.heights_m();
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<float> noise(-0.05f, 0.05f);
  for (float& h : heights) h += noise(rng);
  world.terrain =
      Heightfield(world.terrain.cols(), world.terrain.rows(), world.terrain.resolution_m(),
                  world.terrain.origin_xy(), std::move(heights));
  RenderOptions options;
  options.full_resolution_distance_m = 1.0;
  options.max_terrain_error_px = 40.0;
  StereoRenderer renderer(world, StereoCameraOptions(), options);
  for (const double yaw : {0.0, 0.7, 2.0}) {
    RenderedStereoFrame frame;
    renderer.Render(BodyPose(world, 0.3, 0.2, yaw), {}, 0, &frame);
    // Rows from 150 down look at the ground within ~5 m.
    const cv::Mat lower = frame.depth0_m.rowRange(150, frame.depth0_m.rows);
    EXPECT_EQ(cv::countNonZero(lower == 0.0f), 0) << "yaw " << yaw;
    EXPECT_GT(renderer.last_patch_count(), 20);
  }
}

// ------------------------------------------------------------------ tags --

// DetectTags (tag_detection.h) shifts apriltag's corners (pixel centres at
// integer + 0.5) to OpenCV's convention (integers). The shift is established
// on an ideal, pixel-aligned image below, then used for the rendered tags.

// Largest distance from each detected corner to the nearest of `expected`.
double MaxCornerError(const Detection& detection, const std::vector<Eigen::Vector2d>& expected) {
  double worst = 0.0;
  for (const Eigen::Vector2d& c : detection.corners_px) {
    double best = std::numeric_limits<double>::infinity();
    for (const Eigen::Vector2d& e : expected) best = std::min(best, (c - e).norm());
    worst = std::max(worst, best);
  }
  return worst;
}

TEST(ApriltagConventionTest, CornersAreReportedWithHalfPixelOffset) {
  // An ideal tag, 8 px per cell, pasted at an integer offset: the outer
  // corner of the black border is at pixel edge 100 + 8, i.e. at 107.5 in
  // OpenCV's convention.
  apriltag_family_t* family = tag36h11_create();
  image_u8_t* tag = apriltag_to_image(family, 3);
  cv::Mat image(300, 300, CV_8UC1, cv::Scalar(255));
  constexpr int kScale = 8;
  for (int y = 0; y < tag->height; ++y) {
    for (int x = 0; x < tag->width; ++x) {
      image(cv::Rect(100 + kScale * x, 100 + kScale * y, kScale, kScale))
          .setTo(tag->buf[y * tag->stride + x]);
    }
  }
  // image_u8_destroy is not exported by Debian's build: free as it would.
  std::free(tag->buf);
  std::free(tag);
  tag36h11_destroy(family);
  const std::vector<Detection> detections = DetectTags(image);
  ASSERT_EQ(detections.size(), 1u);
  EXPECT_EQ(detections[0].id, 3);
  const double lo = 100 + kScale - 0.5;
  const double hi = 100 + 9 * kScale - 0.5;
  const std::vector<Eigen::Vector2d> expected = {{lo, lo}, {hi, lo}, {hi, hi}, {lo, hi}};
  // With the half-pixel offset the corners are within the detector's own
  // small bias (about 0.1 px towards the origin); without it 0.4 px off.
  EXPECT_LT(MaxCornerError(detections[0], expected), 0.2);
}

// A world with two tag carriers about 3 m in front of the camera: one facing
// it squarely, one turned by 35 degrees.
struct TagScene {
  World world;
  Eigen::Isometry3d T_world_body;
  std::vector<std::pair<int, Eigen::Isometry3d>> tags;  // id, T_world_tag
  double tag_size_m = 0.16;
};

TagScene MakeTagScene() {
  TagScene scene;
  scene.world = MakeTestWorld(TestWorldOptions());
  scene.T_world_body = BodyPose(scene.world, 0.5, 0.5, 0.2);
  const StereoCameraOptions camera;
  const Eigen::Isometry3d T_world_cam0 = scene.T_world_body * camera.T_body_cam0;
  const Eigen::Isometry3d T_cam0_body = camera.T_body_cam0.inverse();
  // Tag centres 3 m ahead of the camera (body frame, about the camera's
  // height above the ground), one squarely facing the camera, one turned.
  const std::array<std::tuple<int, Eigen::Vector3d, double>, 2> placements = {
      {{5, Eigen::Vector3d(3.25, 0.5, 0.45), 0.0}, {42, Eigen::Vector3d(3.2, -0.55, 0.4), 35.0}}};
  for (const auto& [id, p_body, turn_deg] : placements) {
    // Tag frame: x right, y down, z into the tag. Facing the camera: z along
    // the line of sight, x horizontal (perpendicular to it and to body z).
    const Eigen::Vector3d p_cam0 = T_cam0_body * p_body;
    const Eigen::Vector3d z_axis = p_cam0.normalized();
    const Eigen::Vector3d down_cam0 = -T_cam0_body.linear() * Eigen::Vector3d::UnitZ();
    const Eigen::Vector3d x_axis = down_cam0.cross(z_axis).normalized();
    Eigen::Matrix3d R_cam0_tag;
    R_cam0_tag << x_axis, z_axis.cross(x_axis), z_axis;
    Eigen::Isometry3d T_cam0_tag = Eigen::Isometry3d::Identity();
    T_cam0_tag.linear() =
        R_cam0_tag *
        Eigen::AngleAxisd(turn_deg * M_PI / 180.0, Eigen::Vector3d::UnitY()).toRotationMatrix();
    T_cam0_tag.translation() = p_cam0;
    TagCarrier carrier;
    carrier.name = "post_" + std::to_string(id);
    carrier.is_static = true;
    carrier.T_world_carrier = T_world_cam0 * T_cam0_tag;
    // A head box behind the tag; the tag sits 1 mm in front of its face.
    Box head;
    head.center_carrier = Eigen::Vector3d(0.0, 0.0, 0.001 + 0.05);
    head.size_m = Eigen::Vector3d(0.3, 0.3, 0.1);
    head.albedo = 0.3;
    carrier.boxes.push_back(head);
    TagMarker tag;
    tag.id = id;
    tag.size_m = scene.tag_size_m;
    tag.carrier = carrier.name;
    carrier.tags.push_back(tag);
    scene.world.carriers.push_back(carrier);
    scene.tags.emplace_back(id, carrier.T_world_carrier);
  }
  return scene;
}

TEST(TagRenderTest, ApriltagDetectsRenderedTagsAtThreeMetresWithSubPixelCorners) {
  const TagScene scene = MakeTagScene();
  const StereoCameraOptions camera;
  StereoRenderer renderer(scene.world, camera);
  RenderedStereoFrame frame;
  renderer.Render(scene.T_world_body, {}, 0, &frame);
  const std::vector<Detection> detections = DetectTags(frame.cam0);

  cv::Mat K;
  cv::eigen2cv(camera.CameraMatrix(), K);
  const std::array<double, 4> d = camera.DistortionCoeffs();
  const cv::Mat D = (cv::Mat_<double>(1, 4) << d[0], d[1], d[2], d[3]);
  const Eigen::Isometry3d T_cam0_world = (scene.T_world_body * camera.T_body_cam0).inverse();
  for (const auto& [id, T_world_tag] : scene.tags) {
    const Eigen::Isometry3d T_cam0_tag = T_cam0_world * T_world_tag;
    std::vector<cv::Point3d> object;
    const double h = 0.5 * scene.tag_size_m;
    for (const auto& [x, y] : {std::pair{-h, h}, {h, h}, {h, -h}, {-h, -h}}) {
      object.emplace_back(x, y, 0.0);
    }
    cv::Mat rvec, tvec, R;
    cv::eigen2cv(Eigen::Matrix3d(T_cam0_tag.linear()), R);
    cv::Rodrigues(R, rvec);
    cv::eigen2cv(Eigen::Vector3d(T_cam0_tag.translation()), tvec);
    std::vector<cv::Point2d> projected;
    cv::projectPoints(object, rvec, tvec, K, D, projected);
    std::vector<Eigen::Vector2d> expected;
    for (std::size_t i = 0; i < projected.size(); ++i) {
      expected.emplace_back(projected[i].x, projected[i].y);
      // The renderer's own projection agrees with OpenCV's.
      Eigen::Vector2d mine;
      ASSERT_TRUE(ProjectToPixel(
          camera, T_cam0_tag * Eigen::Vector3d(object[i].x, object[i].y, 0.0), &mine));
      EXPECT_LT((mine - expected.back()).norm(), 1e-9);
    }
    const auto found = std::find_if(detections.begin(), detections.end(),
                                    [id = id](const Detection& det) { return det.id == id; });
    ASSERT_NE(found, detections.end()) << "tag " << id << " not detected";
    const double error = MaxCornerError(*found, expected);
    std::printf("tag %d at %.2f m: max corner error %.3f px\n", id, T_cam0_tag.translation().norm(),
                error);
    EXPECT_LT(error, 1.0);
  }
  EXPECT_EQ(detections.size(), scene.tags.size());
}

TEST(TagRenderTest, GeneratedLandmarkPostTagIsDetectedAtThreeMetres) {
  // The world generator's own post, to check the carrier/tag conventions of
  // the world contract end to end: a rover 3 m in front of a post face.
  WorldOptions world_options;
  world_options.size_m = 30.0;
  world_options.rock_count = 0;
  world_options.crater_count = 0;
  world_options.landmark_post_count = 2;
  const World world = World::Generate(world_options, 3);
  ASSERT_FALSE(world.carriers.empty());
  const TagCarrier& post = world.carriers.front();
  // The face looking most towards the middle of the site, so the rover fits.
  const Eigen::Vector3d to_centre = -post.T_world_carrier.translation().normalized();
  const TagMarker* best = nullptr;
  Eigen::Vector3d outward_world = Eigen::Vector3d::Zero();
  for (const TagMarker& tag : post.tags) {
    const Eigen::Vector3d n = -(post.T_world_carrier * tag.T_carrier_tag).linear().col(2);
    if (best == nullptr || n.dot(to_centre) > outward_world.dot(to_centre)) {
      best = &tag;
      outward_world = n;
    }
  }
  const Eigen::Isometry3d T_world_tag = post.T_world_carrier * best->T_carrier_tag;
  const Eigen::Vector2d facing = -outward_world.head<2>().normalized();
  const StereoCameraOptions camera;
  // Body placed so that cam0 (0.3 m ahead of the body origin) is 3 m from the tag.
  const Eigen::Vector2d body_xy = T_world_tag.translation().head<2>() - 3.3 * facing;
  const Eigen::Isometry3d T_world_body =
      BodyPose(world, body_xy.x(), body_xy.y(), std::atan2(facing.y(), facing.x()));
  StereoRenderer renderer(world, camera);
  std::vector<Eigen::Isometry3d> moving;
  for (const TagCarrier& c : world.carriers) {
    if (!c.is_static) moving.push_back(c.T_world_carrier);
  }
  RenderedStereoFrame frame;
  renderer.Render(T_world_body, moving, 0, &frame);
  const std::vector<Detection> detections = DetectTags(frame.cam0);
  const auto found = std::find_if(detections.begin(), detections.end(),
                                  [&](const Detection& d) { return d.id == best->id; });
  ASSERT_NE(found, detections.end()) << "tag " << best->id << " not detected";
  const Eigen::Isometry3d T_cam0_tag = (T_world_body * camera.T_body_cam0).inverse() * T_world_tag;
  std::vector<Eigen::Vector2d> expected;
  const double h = 0.5 * best->size_m;
  for (const auto& [x, y] : {std::pair{-h, h}, {h, h}, {h, -h}, {-h, -h}}) {
    Eigen::Vector2d uv;
    ASSERT_TRUE(ProjectToPixel(camera, T_cam0_tag * Eigen::Vector3d(x, y, 0.0), &uv));
    expected.push_back(uv);
  }
  const double error = MaxCornerError(*found, expected);
  std::printf("generated post tag %d at %.2f m: max corner error %.3f px\n", best->id,
              T_cam0_tag.translation().norm(), error);
  EXPECT_LT(error, 1.0);
}

}  // namespace
}  // namespace rover::sim
