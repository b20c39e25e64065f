// Obstacle ground truth: the rule on synthetic terrain and on a generated world.

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "hil/sim/world/world.h"
#include "tests/hil/sim/world/test_worlds.h"

namespace rover::sim {
namespace {

using testing::SmallWorld;

// A 10 m x 10 m world at 5 cm with heights from `z(x, y)`, no rocks.
World SyntheticWorld(const std::function<double(double, double)>& z) {
  const int n = 201;
  const double res = 0.05;
  std::vector<float> heights;
  for (int iy = 0; iy < n; ++iy) {
    for (int ix = 0; ix < n; ++ix) {
      heights.push_back(static_cast<float>(z(-5.0 + res * ix, -5.0 + res * iy)));
    }
  }
  World world;
  world.terrain = Heightfield(n, n, res, Eigen::Vector2d(-5.0, -5.0), std::move(heights));
  return world;
}

// Codes of the samples within `radius_m` of (x, y).
std::vector<ObstacleCode> CodesNear(const ObstacleGrid& grid, double x, double y, double radius_m) {
  std::vector<ObstacleCode> codes;
  for (int iy = 0; iy < grid.rows; ++iy) {
    for (int ix = 0; ix < grid.cols; ++ix) {
      const double px = grid.origin_xy.x() + grid.resolution_m * ix;
      const double py = grid.origin_xy.y() + grid.resolution_m * iy;
      if (std::hypot(px - x, py - y) <= radius_m) codes.push_back(grid.CodeAt(ix, iy));
    }
  }
  return codes;
}

int Count(const std::vector<ObstacleCode>& codes, ObstacleCode code) {
  int n = 0;
  for (ObstacleCode c : codes) n += c == code ? 1 : 0;
  return n;
}

TEST(ObstacleRuleTest, GentleSlopeIsFreeSteepSlopeIsSlope) {
  const double deg = 3.14159265358979323846 / 180.0;
  for (double slope_deg : {0.0, 10.0, 20.0, 24.0}) {
    const double g = std::tan(slope_deg * deg);
    const ObstacleGrid grid = ComputeObstacleCells(
        SyntheticWorld([g](double x, double y) { return g * (0.6 * x + 0.8 * y); }));
    const std::vector<ObstacleCode> codes = CodesNear(grid, 0.0, 0.0, 4.0);
    EXPECT_EQ(Count(codes, ObstacleCode::kFree), static_cast<int>(codes.size())) << slope_deg;
  }
  for (double slope_deg : {26.0, 35.0}) {
    const double g = std::tan(slope_deg * deg);
    const ObstacleGrid grid = ComputeObstacleCells(
        SyntheticWorld([g](double x, double y) { return g * (0.8 * x - 0.6 * y); }));
    const std::vector<ObstacleCode> codes = CodesNear(grid, 0.0, 0.0, 4.0);
    EXPECT_EQ(Count(codes, ObstacleCode::kSlope), static_cast<int>(codes.size())) << slope_deg;
  }
}

TEST(ObstacleRuleTest, StepsArePositiveAndDropsNegative) {
  // A step up of 0.15 m at x = 0 on flat ground: a positive obstacle on both
  // sides within the window, never negative (0.15 m < 0.3 m).
  {
    const ObstacleGrid grid =
        ComputeObstacleCells(SyntheticWorld([](double x, double) { return x < 0.0 ? 0.0 : 0.15; }));
    EXPECT_EQ(grid.CodeAt(99, 100), ObstacleCode::kPositive);
    EXPECT_EQ(grid.CodeAt(100, 100), ObstacleCode::kPositive);
    EXPECT_EQ(grid.CodeAt(80, 100), ObstacleCode::kFree);
    EXPECT_EQ(grid.CodeAt(120, 100), ObstacleCode::kFree);
    EXPECT_EQ(Count(CodesNear(grid, 0.0, 0.0, 4.0), ObstacleCode::kNegative), 0);
  }
  // A 5 cm step is climbable.
  {
    const ObstacleGrid grid =
        ComputeObstacleCells(SyntheticWorld([](double x, double) { return x < 0.0 ? 0.0 : 0.05; }));
    const std::vector<ObstacleCode> codes = CodesNear(grid, 0.0, 0.0, 4.0);
    EXPECT_EQ(Count(codes, ObstacleCode::kFree), static_cast<int>(codes.size()));
  }
  // A 0.5 m cliff dropping towards +x: its top edge is negative, its foot positive.
  {
    const ObstacleGrid grid =
        ComputeObstacleCells(SyntheticWorld([](double x, double) { return x < 0.0 ? 0.5 : 0.0; }));
    EXPECT_EQ(grid.CodeAt(99, 100), ObstacleCode::kNegative);   // x = -0.05, the lip
    EXPECT_EQ(grid.CodeAt(96, 100), ObstacleCode::kNegative);   // x = -0.2, within 0.25 m
    EXPECT_EQ(grid.CodeAt(100, 100), ObstacleCode::kPositive);  // x = 0, the foot
    EXPECT_EQ(grid.CodeAt(90, 100), ObstacleCode::kFree);
    EXPECT_EQ(grid.CodeAt(110, 100), ObstacleCode::kFree);
  }
}

TEST(ObstacleRuleTest, RockCellsArePositiveWhole) {
  World world = SyntheticWorld([](double x, double y) { return 0.1 * x + 0.05 * y; });
  Rock rock;
  rock.center_xy = Eigen::Vector2d(1.0, -1.0);
  rock.radius_m = 0.8;
  rock.height_m = 0.5;
  rock.shape_exponent = 4.0;  // flat-topped: the top alone would not look like a step
  world.rocks.push_back(rock);
  const ObstacleGrid grid = ComputeObstacleCells(world);
  const std::vector<ObstacleCode> codes = CodesNear(grid, 1.0, -1.0, 0.6);
  EXPECT_EQ(Count(codes, ObstacleCode::kPositive), static_cast<int>(codes.size()));
  const std::vector<ObstacleCode> far_codes = CodesNear(grid, -3.0, 2.0, 1.0);
  EXPECT_EQ(Count(far_codes, ObstacleCode::kFree), static_cast<int>(far_codes.size()));
}

TEST(ObstacleRuleTest, GeneratedWorldFlagsRocksAndRimButNotGentleGround) {
  const World& world = SmallWorld();
  const ObstacleGrid grid = ComputeObstacleCells(world);
  ASSERT_EQ(grid.cols, world.terrain.cols());
  ASSERT_EQ(grid.rows, world.terrain.rows());
  ASSERT_EQ(grid.codes.size(), world.terrain.heights_m().size());
  const auto code_at = [&](const Eigen::Vector2d& p) {
    return grid.CodeAt(
        static_cast<int>(std::lround((p.x() - grid.origin_xy.x()) / grid.resolution_m)),
        static_cast<int>(std::lround((p.y() - grid.origin_xy.y()) / grid.resolution_m)));
  };
  for (const Rock& rock : world.rocks) {
    EXPECT_EQ(code_at(rock.center_xy), ObstacleCode::kPositive) << rock.center_xy.transpose();
  }
  // Along every radial line the scarp top is negative.
  const Crater& crater = world.craters.at(0);
  for (int k = 0; k < 72; ++k) {
    const double a = 6.283185307179586 * k / 72;
    const Eigen::Vector2d u(std::cos(a), std::sin(a));
    bool negative = false;
    for (double d = crater.radius_m - crater.scarp_width_m; d <= crater.radius_m + 0.3; d += 0.02) {
      negative = negative || code_at(crater.center_xy + d * u) == ObstacleCode::kNegative;
    }
    EXPECT_TRUE(negative) << "direction " << k;
  }
  // Away from rocks and the crater the ground (slopes <= 20 degrees, cm
  // roughness) is free throughout.
  int checked = 0;
  for (int iy = 0; iy < grid.rows; iy += 3) {
    for (int ix = 0; ix < grid.cols; ix += 3) {
      const Eigen::Vector2d p(grid.origin_xy.x() + grid.resolution_m * ix,
                              grid.origin_xy.y() + grid.resolution_m * iy);
      if (testing::NearRockOrCrater(world, p, 0.5)) continue;
      ++checked;
      ASSERT_EQ(grid.CodeAt(ix, iy), ObstacleCode::kFree) << p.transpose();
    }
  }
  EXPECT_GT(checked, 20000);
  // The start is free.
  for (ObstacleCode c : CodesNear(grid, 0.0, 0.0, 3.0)) ASSERT_EQ(c, ObstacleCode::kFree);
}

TEST(ObstacleRuleTest, DescriptionStatesTheParameters) {
  ObstacleRuleOptions rule;
  rule.step_height_m = 0.125;
  const std::string text = DescribeObstacleRule(rule);
  EXPECT_NE(text.find("0.125 m"), std::string::npos);
  EXPECT_NE(text.find("25 degrees"), std::string::npos);
  EXPECT_NE(text.find("0.3 m below"), std::string::npos);
}

}  // namespace
}  // namespace rover::sim
