#include "mapping/terrain/negative_edge_detector.h"

#include <gtest/gtest.h>

#include "tests/mapping/terrain/terrain_test_scene.h"

namespace rover::mapping {
namespace {

using testing::CameraPose;
using testing::RenderDisparity;
using testing::SmallHead;

std::vector<NegativeEdge> EdgesOf(const std::function<double(double, double)>& terrain) {
  const RectifiedStereo s = SmallHead();
  const StereoErrorModel model(s);
  const Eigen::Isometry3d T = CameraPose(1.0, 25.0);
  const DepthImage depth =
      DepthImage::FromDisparity(RenderDisparity(s, T, terrain), model, {.max_depth_sigma_m = 1.0});
  return NegativeEdgeDetector({}).Detect(depth, T);
}

TEST(NegativeEdgeDetectorTest, FlagsTheTopOfACliffAndNothingOnLevelGround) {
  EXPECT_TRUE(EdgesOf([](double, double) { return 0.0; }).empty());
  // A 1 m drop 1.5 m ahead: the ground beyond is seen, far below. (The
  // minimal slope over an edge is the viewing ray's, 1 m / 1.5 m here: an
  // edge farther than 1 m / tan(25 deg) = 2.1 m cannot be proven steep.)
  const auto edges = EdgesOf([](double x, double) { return x < 1.5 ? 0.0 : -1.0; });
  ASSERT_FALSE(edges.empty());
  for (const NegativeEdge& e : edges) {
    EXPECT_NEAR(e.q_gravity.x(), 1.5, 0.05) << "near side of the edge";
    EXPECT_NEAR(e.q_gravity.z(), 0.0, 0.02);
    EXPECT_GT(e.min_slope, std::tan(25.0 * M_PI / 180.0));
  }
}

TEST(NegativeEdgeDetectorTest, CannotProveAFarEdgeSteepOrAGentleSlope) {
  // The same drop 3 m ahead: seen at a shallower angle than 25 degrees.
  EXPECT_TRUE(EdgesOf([](double x, double) { return x < 3.0 ? 0.0 : -1.0; }).empty());
  // 10 degrees down from 1.5 m on: traversable.
  const auto edges = EdgesOf(
      [](double x, double) { return x < 1.5 ? 0.0 : -(x - 1.5) * std::tan(10.0 * M_PI / 180.0); });
  EXPECT_TRUE(edges.empty()) << edges.size() << " edges";
}

TEST(NegativeEdgeDetectorTest, GroundDroppingOutOfStereoRangeIsAnEdge) {
  // The ground beyond 3 m is 100 m down: beyond stereo range (zero disparity).
  const auto edges = EdgesOf([](double x, double) { return x < 3.0 ? 0.0 : -100.0; });
  ASSERT_FALSE(edges.empty());
  for (const NegativeEdge& e : edges) {
    EXPECT_NEAR(e.q_gravity.x(), 3.0, 0.1);
    EXPECT_TRUE(std::isinf(e.min_slope));
  }
}

TEST(NegativeEdgeDetectorTest, AWrongMatchAlongASteepRayIsNoEdge) {
  // Level ground; one column's disparity at 1.5 m ahead made 15 % too small
  // over a few rows (a wrong match: 0.35 m farther along its ray). The ray
  // is steeper than 25 degrees, so the jump passes eq. 5.1's slope test;
  // only its size tells it from a drop: on this head (f = 115 px) sigma_z
  // is about 0.2 m there, the fixed 0.2 m threshold takes it, the one with
  // the stereo error (0.5 m) does not. A 1 m drop at the same place stays
  // an edge.
  const RectifiedStereo s = SmallHead();
  const StereoErrorModel model(s);
  const Eigen::Isometry3d T = CameraPose(1.0, 25.0);
  cv::Mat disparity = RenderDisparity(s, T, [](double, double) { return 0.0; });
  const int u = s.width_px / 2;
  int v_hit = -1;  // the nearest row beyond 1.5 m (rows run from far to near)
  for (int v = s.height_px - 1; v >= 0 && v_hit < 0; --v) {
    const Eigen::Vector3d p = T * s.Triangulate(u, v, disparity.at<int16_t>(v, u) / 16.0);
    if (disparity.at<int16_t>(v, u) > 0 && p.x() > 1.5) v_hit = v;
  }
  ASSERT_GT(v_hit, 3);
  for (int v = v_hit - 3; v < v_hit; ++v) {
    disparity.at<int16_t>(v, u) = static_cast<int16_t>(disparity.at<int16_t>(v, u) * 17 / 20);
  }
  const DepthImage depth = DepthImage::FromDisparity(disparity, model, {.max_depth_sigma_m = 1.0});
  EXPECT_FALSE(NegativeEdgeDetector({.error_adaptive = false}).Detect(depth, T).empty());
  EXPECT_TRUE(NegativeEdgeDetector({}).Detect(depth, T).empty());
  const DepthImage drop = DepthImage::FromDisparity(
      RenderDisparity(s, T, [](double x, double) { return x < 1.5 ? 0.0 : -1.0; }), model,
      {.max_depth_sigma_m = 1.0});
  EXPECT_FALSE(NegativeEdgeDetector({}).Detect(drop, T).empty());
}

TEST(NegativeEdgeDetectorTest, RejectsBadOptions) {
  EXPECT_THROW(NegativeEdgeDetector({.depth_jump_m = 0.0}), std::invalid_argument);
  EXPECT_THROW(NegativeEdgeDetector({.max_slope_deg = 90.0}), std::invalid_argument);
}

}  // namespace
}  // namespace rover::mapping
