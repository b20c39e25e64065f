#include "mapping/terrain/step_classifier.h"

#include <gtest/gtest.h>

#include "tests/mapping/terrain/terrain_test_scene.h"

namespace rover::mapping {
namespace {

using testing::CameraPose;
using testing::RenderDisparity;
using testing::SmallHead;

struct Result {
  StepGrid grid;
  HeightMap map;
};

Result Classify(const std::function<double(double, double)>& terrain, bool adaptive,
                double pixel_error_px = 0.5) {
  const RectifiedStereo s = SmallHead(2);
  const StereoErrorModel model(s, pixel_error_px);
  const Eigen::Isometry3d T = CameraPose(1.0, 25.0);
  const DepthImage depth =
      DepthImage::FromDisparity(RenderDisparity(s, T, terrain), model, {.max_depth_sigma_m = 5.0});
  HeightMap map = HeightMap::Build(depth, T, {});
  const StepClassifier classifier({.error_adaptive = adaptive}, model);
  return {classifier.Classify(map, T), std::move(map)};
}

// Obstacle cells whose centre lies within `box` (x0, x1, y0, y1) and outside.
std::pair<int, int> CountObstacles(const Result& r, double x0, double x1, double y0, double y1) {
  int inside = 0, outside = 0;
  for (int iy = 0; iy < r.grid.rows; ++iy) {
    for (int ix = 0; ix < r.grid.cols; ++ix) {
      if (!r.grid.Known(ix, iy) || !r.grid.Obstacle(ix, iy)) continue;
      const Eigen::Vector3d c = r.map.CellPoint(ix, iy);
      const bool in = c.x() > x0 && c.x() < x1 && c.y() > y0 && c.y() < y1;
      (in ? inside : outside) += 1;
    }
  }
  return {inside, outside};
}

TEST(StepClassifierTest, ARockIsAnObstacleAndLevelGroundIsNot) {
  const auto flat = Classify([](double, double) { return 0.0; }, true);
  EXPECT_EQ(CountObstacles(flat, -100, 100, -100, 100).second, 0);
  // A 0.3 m block, 0.4 m square, 2.5 m ahead.
  const auto rock = Classify(
      [](double x, double y) { return (x > 2.3 && x < 2.7 && std::abs(y) < 0.2) ? 0.3 : 0.0; },
      true);
  const auto [inside, outside] = CountObstacles(rock, 2.0, 3.0, -0.5, 0.5);
  EXPECT_GT(inside, 4);
  EXPECT_EQ(outside, 0);
}

TEST(StepClassifierTest, TheErrorAdaptiveThresholdGrowsWithDistance) {
  // A 0.2 m step (over h_max = 0.1 m) on this half-resolution head (f =
  // 230 px, b = 0.11 m). 4 m ahead the stereo error of the height
  // difference across it (thesis: 0.5 px) is about 0.14 m: the adaptive
  // threshold does not call it (stereo cannot tell it from noise there), a
  // fixed one does. 1.4 m ahead (error about 0.05 m) both call it.
  const auto far_step = [](double x, double) { return x > 4.0 ? 0.2 : 0.0; };
  const auto near_step = [](double x, double) { return x > 1.4 ? 0.2 : 0.0; };
  const int adaptive_far = CountObstacles(Classify(far_step, true), 3.7, 4.3, -9, 9).first;
  const int fixed_far = CountObstacles(Classify(far_step, false), 3.7, 4.3, -9, 9).first;
  EXPECT_GT(fixed_far, 20);
  // At most a stray cell where the median filter meets the end of the data.
  EXPECT_LE(adaptive_far, 1) << "fixed threshold: " << fixed_far;
  EXPECT_GT(CountObstacles(Classify(near_step, true), 1.2, 1.6, -9, 9).first, 0);
}

TEST(HeightMapTest, SpikeRemovalDropsALoneSpikeButKeepsAStep) {
  // Level ground with one cell's points lifted 0.5 m (wrong matches that
  // landed together), and a real 0.25 m step further on.
  const auto terrain = [](double x, double y) {
    if (x > 1.5 && x < 1.55 && y > 0.0 && y < 0.05) return 0.5;
    return x > 2.1 ? 0.25 : 0.0;
  };
  const auto spike_obstacles = [&](bool remove_spikes) {
    const RectifiedStereo s = SmallHead(2);
    const Eigen::Isometry3d T = CameraPose(1.0, 30.0);
    const DepthImage depth =
        DepthImage::FromDisparity(RenderDisparity(s, T, terrain), StereoErrorModel(s), {});
    HeightMapOptions options;
    options.spike_tolerance_m = remove_spikes ? 0.05 : 0.0;
    const HeightMap map = HeightMap::Build(depth, T, options);
    const StereoErrorModel model(s);
    const StepGrid steps = StepClassifier({}, model).Classify(map, T);
    int spike = 0, step = 0;
    for (int iy = 0; iy < steps.rows; ++iy) {
      for (int ix = 0; ix < steps.cols; ++ix) {
        if (!steps.Obstacle(ix, iy)) continue;
        const Eigen::Vector3d c = map.CellPoint(ix, iy);
        if (c.x() > 1.2 && c.x() < 1.85 && std::abs(c.y()) < 0.35) ++spike;
        if (c.x() > 1.95 && c.x() < 2.25) ++step;
      }
    }
    return std::make_pair(spike, step);
  };
  const auto [spike_raw, step_raw] = spike_obstacles(false);
  const auto [spike_removed, step_kept] = spike_obstacles(true);
  EXPECT_GT(spike_raw, 10) << "unfiltered, the spike makes every window around it a step";
  EXPECT_EQ(spike_removed, 0);
  EXPECT_GT(step_kept, 0.9 * step_raw) << "the real step stays";
}

TEST(StepClassifierTest, RejectsBadOptions) {
  const StereoErrorModel model(SmallHead());
  EXPECT_THROW(StepClassifier({.h_max_m = 0.0}, model), std::invalid_argument);
  EXPECT_THROW(StepClassifier({.window_cells = 1}, model), std::invalid_argument);
}

}  // namespace
}  // namespace rover::mapping

#include "mapping/terrain/traversability_grid.h"

namespace rover::mapping {
namespace {

StepGrid OneCell(double x, double y, float value) {
  StepGrid g;
  g.cols = g.rows = 1;
  g.resolution_m = 0.05;
  g.origin_xy = {x, y};
  g.traversability = {value};
  return g;
}

TEST(TraversabilityGridTest, LowPassFiltersObservationsAndScrollsWithTheRover) {
  TraversabilityGrid grid({.half_extent_m = 1.0, .alpha = 0.5});
  EXPECT_LT(grid.ValueAt({0.52, 0.02}), 0.0f) << "unknown before any observation";
  grid.Add(OneCell(0.50, 0.0, 2.0f), {});
  EXPECT_FLOAT_EQ(grid.ValueAt({0.52, 0.02}), 2.0f) << "the first observation is taken as is";
  grid.Add(OneCell(0.50, 0.0, 0.0f), {});
  EXPECT_FLOAT_EQ(grid.ValueAt({0.52, 0.02}), 1.0f) << "then blended with alpha 0.5";
  // The rover moves 0.6 m along x: the cell stays where it is in the world.
  grid.Recentre({0.6, 0.0});
  EXPECT_FLOAT_EQ(grid.ValueAt({0.52, 0.02}), 1.0f);
  // ... and 3 m further it has scrolled off (the grid spans +-1 m).
  grid.Recentre({3.6, 0.0});
  EXPECT_LT(grid.ValueAt({0.52, 0.02}), 0.0f);
  grid.Recentre({0.6, 0.0});
  EXPECT_LT(grid.ValueAt({0.52, 0.02}), 0.0f) << "forgotten, not kept";
}

TEST(TraversabilityGridTest, NegativeEdgesAreUntraversable) {
  TraversabilityGrid grid({});
  NegativeEdge edge;
  edge.q_gravity = {1.0, -0.3, 0.0};
  grid.Add(OneCell(1.0, -0.3, 0.2f), {edge});
  EXPECT_GT(grid.ValueAt({1.01, -0.29}), 1.0f);
  EXPECT_THROW(TraversabilityGrid({.alpha = 0.0}), std::invalid_argument);
}

}  // namespace
}  // namespace rover::mapping
