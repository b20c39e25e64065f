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

TEST(NegativeEdgeDetectorTest, RejectsBadOptions) {
  EXPECT_THROW(NegativeEdgeDetector({.depth_jump_m = 0.0}), std::invalid_argument);
  EXPECT_THROW(NegativeEdgeDetector({.max_slope_deg = 90.0}), std::invalid_argument);
}

}  // namespace
}  // namespace rover::mapping
