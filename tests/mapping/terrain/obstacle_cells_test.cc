// Whole obstacles from the step test's edges (ObstacleCellMarker) and their
// confirmation by a second image (TraversabilityGrid::KeepConfirmed), on
// ray-marched depth images.

#include "mapping/terrain/obstacle_cells.h"

#include <gtest/gtest.h>

#include "mapping/terrain/traversability_grid.h"
#include "tests/mapping/terrain/terrain_test_scene.h"

namespace rover::mapping {
namespace {

using testing::CameraPose;
using testing::RenderDisparity;
using testing::SmallHead;

struct Scene {
  HeightMap map;
  StepGrid steps;
};

Scene Classify(const std::function<double(double, double)>& terrain) {
  const RectifiedStereo s = SmallHead(2);
  const StereoErrorModel model(s);
  const Eigen::Isometry3d T = CameraPose(1.0, 25.0);
  const DepthImage depth =
      DepthImage::FromDisparity(RenderDisparity(s, T, terrain), model, {.max_depth_sigma_m = 1.0});
  Scene scene{HeightMap::Build(depth, T, {}), {}};
  scene.steps = StepClassifier({}, model).Classify(scene.map, T);
  return scene;
}

// Known cells with centres inside the box, and how many of them are
// obstacles in `cells`, and in the step grid alone.
struct Count {
  int known = 0;
  int obstacles = 0;
  int steps = 0;
};

Count CountBox(const Scene& scene, const ObstacleCells& cells, double x0, double x1, double y0,
               double y1) {
  Count c;
  for (int iy = 0; iy < scene.map.rows(); ++iy) {
    for (int ix = 0; ix < scene.map.cols(); ++ix) {
      const Eigen::Vector3d p = scene.map.CellPoint(ix, iy);
      if (!scene.map.Has(ix, iy) || p.x() < x0 || p.x() > x1 || p.y() < y0 || p.y() > y1) continue;
      ++c.known;
      if (cells.Obstacle(ix, iy)) ++c.obstacles;
      if (scene.steps.Obstacle(ix, iy)) ++c.steps;
    }
  }
  return c;
}

// A boulder with a level top, `radius_m` round and `height_m` tall, centred
// `ahead_m` in front of the camera.
std::function<double(double, double)> Boulder(double ahead_m, double y_m, double radius_m,
                                              double height_m) {
  return [=](double x, double y) {
    return std::hypot(x - ahead_m, y - y_m) < radius_m ? height_m : 0.0;
  };
}

TEST(ObstacleCellMarkerTest, ABouldersLevelTopIsFlaggedWhole) {
  // 1.2 m across: its top is wider than two step windows and the closing
  // disc, so the step test leaves its middle free.
  const Scene scene = Classify(Boulder(2.6, 0.0, 0.6, 0.35));
  ObstacleCells plain, whole;
  ObstacleCellMarker({.fill_raised_regions = false}, {}).Mark(scene.steps, scene.map, &plain);
  ObstacleCellMarker marker({}, {});
  marker.Mark(scene.steps, scene.map, &whole);
  const Count top_plain = CountBox(scene, plain, 2.4, 2.8, -0.2, 0.2);
  const Count top_whole = CountBox(scene, whole, 2.4, 2.8, -0.2, 0.2);
  ASSERT_GT(top_whole.known, 20) << "the camera sees the top";
  EXPECT_EQ(top_plain.steps, 0) << "level within every step window";
  EXPECT_LT(top_plain.obstacles, top_plain.known / 2) << "too wide for the closing";
  EXPECT_EQ(top_whole.obstacles, top_whole.known);
  EXPECT_EQ(whole.raised_regions, 1);
  // Level ground around it stays free.
  EXPECT_EQ(CountBox(scene, whole, 1.0, 1.7, -2.0, 2.0).obstacles, 0);
  EXPECT_EQ(CountBox(scene, whole, 1.0, 3.5, 1.0, 2.0).obstacles, 0);
}

TEST(ObstacleCellMarkerTest, GroundBetweenRocksAndTheTopOfATerraceStayFree) {
  // Two boulders 1.4 m apart: the ground between them is bounded by their
  // flanks on two sides, but lies at their feet.
  const auto a = Boulder(2.4, -0.8, 0.35, 0.3);
  const auto b = Boulder(2.4, 0.8, 0.35, 0.3);
  const Scene rocks = Classify([&](double x, double y) { return a(x, y) + b(x, y); });
  ObstacleCells cells;
  ObstacleCellMarker marker({}, {});
  marker.Mark(rocks.steps, rocks.map, &cells);
  EXPECT_EQ(CountBox(rocks, cells, 2.0, 2.8, -0.3, 0.3).obstacles, 0);
  // A 0.3 m terrace from 2.2 m on, wider than any boulder: its edge is a
  // step, its top is ground.
  const Scene terrace = Classify([](double x, double) { return x > 2.2 ? 0.3 : 0.0; });
  marker.Mark(terrace.steps, terrace.map, &cells);
  const Count edge = CountBox(terrace, cells, 2.1, 2.3, -0.5, 0.5);
  EXPECT_GT(edge.obstacles, 0);
  EXPECT_EQ(CountBox(terrace, cells, 2.6, 3.5, -1.0, 1.0).obstacles, 0);
  EXPECT_EQ(cells.raised_regions, 0);
}

TEST(ObstacleCellMarkerTest, RejectsBadOptions) {
  EXPECT_THROW(ObstacleCellMarker({.closing_radius_m = -0.1}, {}), std::invalid_argument);
  EXPECT_THROW(ObstacleCellMarker({.max_raised_region_m = 0.0}, {}), std::invalid_argument);
  EXPECT_THROW(ObstacleCellMarker({}, {.window_cells = 1}), std::invalid_argument);
}

// Obstacle cells over a 2 x 2 m grid at the origin: two blobs.
ObstacleCells TwoBlobs(bool with_second) {
  ObstacleCells cells;
  cells.cols = cells.rows = 40;
  cells.resolution_m = 0.05;
  cells.origin_xy = {0.0, 0.0};
  cells.mask = cv::Mat::zeros(40, 40, CV_8UC1);
  cells.mask(cv::Rect(5, 5, 4, 4)).setTo(255);
  if (with_second) cells.mask(cv::Rect(20, 20, 6, 3)).setTo(255);
  return cells;
}

TEST(TraversabilityGridTest, AnObstacleIsKeptOnceASecondImageConfirmsIt) {
  TraversabilityGrid grid({.half_extent_m = 2.0});
  grid.Recentre({1.0, 1.0});
  ObstacleCells first = TwoBlobs(false);
  grid.CountObstacles(first);
  grid.KeepConfirmed(2, &first);
  EXPECT_EQ(cv::countNonZero(first.mask), 0) << "seen once: not yet";
  // The second image sees the first blob again, grown by a cell (a rock
  // seen closer), and a new blob (a wrong match).
  ObstacleCells second = TwoBlobs(true);
  second.mask(cv::Rect(4, 5, 1, 4)).setTo(255);
  grid.CountObstacles(second);
  EXPECT_EQ(grid.ObstacleImages({0.27, 0.27}), 2);
  EXPECT_EQ(grid.ObstacleImages({1.02, 1.02}), 1);
  grid.KeepConfirmed(2, &second);
  EXPECT_EQ(cv::countNonZero(second.mask), 20) << "the whole first blob, its new cells too";
  EXPECT_EQ(second.mask.at<uint8_t>(21, 21), 0) << "the new blob waits for its second look";
  // Counts scroll with the grid like its values.
  grid.Recentre({1.5, 1.0});
  EXPECT_EQ(grid.ObstacleImages({0.27, 0.27}), 2);
  grid.Recentre({5.0, 1.0});
  EXPECT_EQ(grid.ObstacleImages({0.27, 0.27}), 0) << "scrolled off, forgotten";
}

}  // namespace
}  // namespace rover::mapping
