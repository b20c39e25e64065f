// Unit checks of the renderer's parts that need no GL: the lens model, the
// tag pattern, the terrain level-of-detail selection and the sensor model.

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cmath>
#include <cstdlib>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/core/eigen.hpp>
#include <random>
#include <set>
#include <vector>

#include "core/config/config.h"
#include "hil/sim/render/sensor_effects.h"
#include "hil/sim/render/stereo_camera.h"
#include "hil/sim/render/terrain_lod.h"

namespace rover::sim {
namespace {

TEST(StereoCameraTest, DefaultsAreValidAndCam1IsBaselineAlongCam0X) {
  const StereoCameraOptions camera;
  EXPECT_NO_THROW(camera.Validate());
  const Eigen::Isometry3d T_cam0_cam1 = camera.T_body_cam0.inverse() * camera.T_body_cam1();
  EXPECT_TRUE(T_cam0_cam1.linear().isIdentity(1e-12));
  EXPECT_TRUE(T_cam0_cam1.translation().isApprox(Eigen::Vector3d(0.09, 0.0, 0.0), 1e-12));
  // Optical axis forward and 20 degrees down in the body frame; x to the right.
  const Eigen::Vector3d axis_body = camera.T_body_cam0.linear().col(2);
  EXPECT_NEAR(axis_body.x(), std::cos(20.0 * M_PI / 180.0), 1e-12);
  EXPECT_NEAR(axis_body.z(), -std::sin(20.0 * M_PI / 180.0), 1e-12);
  EXPECT_NEAR(camera.T_body_cam0.linear().col(0).y(), -1.0, 1e-12);
  EXPECT_NEAR(camera.T_body_cam0.linear().determinant(), 1.0, 1e-12);
}

TEST(StereoCameraTest, RejectsOutOfRangeOptions) {
  StereoCameraOptions camera;
  camera.width_px = 1300;
  EXPECT_THROW(camera.Validate(), std::invalid_argument);
  camera = StereoCameraOptions();
  camera.rate_hz = 30.0;
  EXPECT_THROW(camera.Validate(), std::invalid_argument);
  camera = StereoCameraOptions();
  camera.width_px = 1292;
  camera.height_px = 964;
  camera.cx_px = 645.5;
  camera.cy_px = 481.5;
  camera.fx_px = camera.fy_px = 790.0;
  EXPECT_NO_THROW(camera.Validate());
}

TEST(StereoCameraTest, LoadsFromYaml) {
  const ConfigNode node = ConfigNode::LoadString(
      "width_px: 1292\nheight_px: 964\nfx_px: 800\nfy_px: 801\ncx_px: 645.5\ncy_px: 481.5\n"
      "baseline_m: 0.12\nrate_hz: 20\nk1: -0.2\n",
      "test.yaml");
  const StereoCameraOptions camera = StereoCameraOptions::Load(node);
  EXPECT_EQ(camera.width_px, 1292);
  EXPECT_EQ(camera.fy_px, 801.0);
  EXPECT_EQ(camera.baseline_m, 0.12);
  EXPECT_EQ(camera.k1, -0.2);
  EXPECT_EQ(camera.k2, StereoCameraOptions().k2);
  node.CheckNoUnknownKeys();
}

TEST(StereoCameraTest, UndistortInvertsDistortAcrossTheImage) {
  const StereoCameraOptions camera;
  for (int v = 0; v < camera.height_px; v += 13) {
    for (int u = 0; u < camera.width_px; u += 13) {
      Eigen::Vector3d ray;
      ASSERT_TRUE(PixelToRay(camera, Eigen::Vector2d(u, v), &ray));
      Eigen::Vector2d uv;
      ASSERT_TRUE(ProjectToPixel(camera, 4.0 * ray, &uv));
      EXPECT_LT((uv - Eigen::Vector2d(u, v)).norm(), 1e-8);
    }
  }
}

TEST(StereoCameraTest, ProjectionMatchesOpenCv) {
  const StereoCameraOptions camera;
  cv::Mat K;
  cv::eigen2cv(camera.CameraMatrix(), K);
  const std::array<double, 4> d = camera.DistortionCoeffs();
  const cv::Mat D = (cv::Mat_<double>(1, 4) << d[0], d[1], d[2], d[3]);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> xy(-0.9, 0.9);
  std::vector<cv::Point3d> points;
  for (int i = 0; i < 200; ++i) points.emplace_back(xy(rng), 0.6 * xy(rng), 1.0);
  std::vector<cv::Point2d> projected;
  cv::projectPoints(points, cv::Vec3d::zeros(), cv::Vec3d::zeros(), K, D, projected);
  for (std::size_t i = 0; i < points.size(); ++i) {
    Eigen::Vector2d uv;
    ASSERT_TRUE(
        ProjectToPixel(camera, Eigen::Vector3d(points[i].x, points[i].y, points[i].z), &uv));
    EXPECT_NEAR(uv.x(), projected[i].x, 1e-9);
    EXPECT_NEAR(uv.y(), projected[i].y, 1e-9);
  }
}

// A tilted plane (which every level represents exactly) with one sharp
// bump at `bump_xy` (which only fine levels represent).
Heightfield RampField(int n, double resolution_m, const Eigen::Vector2d& bump_xy) {
  const Eigen::Vector2d origin = Eigen::Vector2d::Constant(-0.5 * resolution_m * (n - 1));
  std::vector<float> heights(static_cast<std::size_t>(n) * static_cast<std::size_t>(n));
  for (int iy = 0; iy < n; ++iy) {
    for (int ix = 0; ix < n; ++ix) {
      const Eigen::Vector2d xy = origin + resolution_m * Eigen::Vector2d(ix, iy);
      const double bump = 0.3 * std::exp(-(xy - bump_xy).squaredNorm() / (2.0 * 0.2 * 0.2));
      heights[static_cast<std::size_t>(iy * n + ix)] =
          static_cast<float>(0.01 * ix - 0.02 * iy + bump);
    }
  }
  return Heightfield(n, n, resolution_m, origin, std::move(heights));
}

TEST(TerrainQuadtreeTest, PatchesCoverTheGridOnceAndMeetTheErrorBound) {
  // 50 m, not a multiple of the patch size.
  const Heightfield terrain = RampField(1001, 0.05, Eigen::Vector2d(15.0, 12.0));
  const TerrainQuadtree tree(terrain);
  const Eigen::Vector3d eye(3.0, -2.0, 1.0);
  TerrainLodParams params;
  params.full_resolution_distance_m = 6.0;
  params.max_error_px = 1.0;
  params.focal_px = 460.0;
  const std::vector<TerrainPatch> patches = tree.Select(eye, params);
  constexpr int kQuads = TerrainQuadtree::kPatchQuads;
  const int slots = (1000 + kQuads - 1) / kQuads;
  std::vector<int> covered(static_cast<std::size_t>(slots * slots), 0);
  int bump_level = -1;
  for (const TerrainPatch& p : patches) {
    const int n = 1 << p.level;
    EXPECT_EQ(p.stride_cells, n);
    for (int y = p.iy0 / kQuads; y < std::min(p.iy0 / kQuads + n, slots); ++y) {
      for (int x = p.ix0 / kQuads; x < std::min(p.ix0 / kQuads + n, slots); ++x) {
        ++covered[static_cast<std::size_t>(y * slots + x)];
      }
    }
    if (p.level > 0) {
      EXPECT_GE(p.distance_m, params.full_resolution_distance_m);
      EXPECT_LE(params.focal_px * p.error_m, params.max_error_px * p.distance_m);
    }
    for (const int s : p.edge_stride_cells) {
      EXPECT_GE(s, p.stride_cells);
    }
    EXPECT_LE(p.min_world.z(), p.max_world.z());
    if (p.min_world.x() <= 15.0 && p.max_world.x() >= 15.0 && p.min_world.y() <= 12.0 &&
        p.max_world.y() >= 12.0) {
      bump_level = p.level;
    }
  }
  for (const int c : covered) EXPECT_EQ(c, 1);
  EXPECT_EQ(patches.front().level, 0);
  for (std::size_t i = 1; i < patches.size(); ++i) {
    EXPECT_LE(patches[i - 1].distance_m, patches[i].distance_m);
  }
  // The plane far away is coarse; the bump at ~20 m keeps a fine level.
  int coarsest = 0;
  for (const TerrainPatch& p : patches) coarsest = std::max(coarsest, p.level);
  EXPECT_GE(coarsest, 4);
  EXPECT_GE(bump_level, 0);
  EXPECT_LE(bump_level, 2);
}

TEST(TerrainQuadtreeTest, BoundsContainEverySample) {
  const Heightfield terrain = RampField(300, 0.1, Eigen::Vector2d(3.0, 4.0));
  const TerrainQuadtree tree(terrain);
  TerrainLodParams params;
  params.full_resolution_distance_m = 5.0;
  for (const TerrainPatch& p : tree.Select(Eigen::Vector3d(0, 0, 0), params)) {
    const int span = TerrainQuadtree::kPatchQuads * p.stride_cells;
    for (int iy = p.iy0; iy <= std::min(p.iy0 + span, terrain.rows() - 1); ++iy) {
      for (int ix = p.ix0; ix <= std::min(p.ix0 + span, terrain.cols() - 1); ++ix) {
        const double z = terrain.HeightAtCell(ix, iy);
        EXPECT_GE(z, p.min_world.z() - 1e-6);
        EXPECT_LE(z, p.max_world.z() + 1e-6);
      }
    }
  }
}

TEST(SensorEffectsTest, NoiseHasTheModelledVarianceAndIsSeeded) {
  StereoCameraOptions camera;
  camera.vignetting_strength = 0.0;
  camera.read_noise_dn = 2.0;
  camera.dn_per_electron = 0.1;
  camera.gain = 2.0;
  SensorEffects effects(camera);
  const double dn_per_radiance = camera.exposure_time_s * camera.gain * camera.sensitivity_dn_per_s;
  const double radiance = 100.0 / dn_per_radiance;  // 100 DN
  const cv::Mat flat(camera.height_px, camera.width_px, CV_32FC1,
                     cv::Scalar(static_cast<float>(radiance)));
  cv::Mat a, b, c;
  effects.Apply(flat, true, 1, &a);
  effects.Apply(flat, true, 1, &b);
  effects.Apply(flat, true, 2, &c);
  EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0.0);
  EXPECT_GT(cv::norm(a, c, cv::NORM_INF), 0.0);
  cv::Scalar mean, stddev;
  cv::meanStdDev(a, mean, stddev);
  // Variance = read^2 + gain * dn_per_electron * signal (+ 1/12 from rounding).
  const double expected_sigma = std::sqrt(4.0 + 2.0 * 0.1 * 100.0 + 1.0 / 12.0);
  EXPECT_NEAR(mean[0], 100.0, 0.05);
  EXPECT_NEAR(stddev[0], expected_sigma, 0.05);
  cv::Mat clean;
  effects.Apply(flat, false, 1, &clean);
  EXPECT_EQ(cv::countNonZero(clean != 100), 0);
}

TEST(SensorEffectsTest, VignettingDarkensTheCorners) {
  StereoCameraOptions camera;
  camera.vignetting_strength = 1.0;
  SensorEffects effects(camera);
  const cv::Mat& gain = effects.vignetted_gain();
  // Full strength is the cos^4 law of the pixel's ray angle.
  const double centre = gain.at<float>(240, 376);
  Eigen::Vector3d corner_ray;
  ASSERT_TRUE(PixelToRay(camera, Eigen::Vector2d(0, 0), &corner_ray));
  EXPECT_NEAR(static_cast<double>(gain.at<float>(0, 0)) / centre, std::pow(corner_ray.z(), 4.0),
              1e-3);
  EXPECT_LT(static_cast<double>(gain.at<float>(0, 0)), 0.2 * centre);
}

}  // namespace
}  // namespace rover::sim
