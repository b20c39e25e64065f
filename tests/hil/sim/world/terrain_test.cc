// Heightfield queries: interpolation, gradient, normals and the ray cast.

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <stdexcept>
#include <vector>

#include "hil/sim/world/world.h"
#include "tests/hil/sim/world/test_worlds.h"

namespace rover::sim {
namespace {

using testing::SmallWorld;

// 3 x 3 samples at 0.5 m with a known bilinear surface in each cell.
Heightfield SmallField() {
  // Row iy = 0 first.
  return Heightfield(3, 3, 0.5, Eigen::Vector2d(-1.0, 2.0),
                     {0.0F, 1.0F, 2.0F,  //
                      0.5F, 0.0F, 1.0F,  //
                      1.0F, 1.0F, 0.0F});
}

TEST(HeightfieldTest, RejectsInconsistentSizes) {
  EXPECT_THROW(Heightfield(3, 3, 0.5, Eigen::Vector2d::Zero(), std::vector<float>(8)),
               std::invalid_argument);
  EXPECT_THROW(Heightfield(1, 3, 0.5, Eigen::Vector2d::Zero(), std::vector<float>(3)),
               std::invalid_argument);
  EXPECT_THROW(Heightfield(2, 2, 0.0, Eigen::Vector2d::Zero(), std::vector<float>(4)),
               std::invalid_argument);
}

TEST(HeightfieldTest, InterpolatesBilinearlyAndClampsOutside) {
  const Heightfield field = SmallField();
  EXPECT_DOUBLE_EQ(field.HeightAt(-1.0, 2.0), 0.0);
  EXPECT_DOUBLE_EQ(field.HeightAt(-0.5, 2.5), 0.0);
  EXPECT_DOUBLE_EQ(field.HeightAt(0.0, 3.0), 0.0);
  EXPECT_DOUBLE_EQ(field.HeightAt(0.0, 2.0), 2.0);
  // Centre of the first cell: mean of its corners 0, 1, 0.5, 0.
  EXPECT_DOUBLE_EQ(field.HeightAt(-0.75, 2.25), 0.375);
  // Clamped to the border outside.
  EXPECT_DOUBLE_EQ(field.HeightAt(-5.0, 2.0), 0.0);
  EXPECT_DOUBLE_EQ(field.HeightAt(9.0, 9.0), 0.0);
  EXPECT_DOUBLE_EQ(field.HeightAt(-0.75, -4.0), 0.5);
  EXPECT_DOUBLE_EQ(field.min_height_m(), 0.0);
  EXPECT_DOUBLE_EQ(field.max_height_m(), 2.0);
  EXPECT_TRUE(field.Contains(-1.0, 2.0));
  EXPECT_TRUE(field.Contains(0.0, 3.0));
  EXPECT_FALSE(field.Contains(0.01, 2.5));
  EXPECT_FALSE(field.Contains(-0.5, 1.99));
}

TEST(HeightfieldTest, GradientMatchesFiniteDifferences) {
  const Heightfield& terrain = SmallWorld().terrain;
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> coordinate(-19.0, 19.0);
  const double h = 1e-6;
  for (int i = 0; i < 200; ++i) {
    const double x = coordinate(rng);
    const double y = coordinate(rng);
    // Stay inside one cell for the difference.
    const double fx = (x - terrain.origin_xy().x()) / terrain.resolution_m();
    const double fy = (y - terrain.origin_xy().y()) / terrain.resolution_m();
    if (fx - std::floor(fx) > 0.99 || fy - std::floor(fy) > 0.99) continue;
    const Eigen::Vector2d g = terrain.GradientAt(x, y);
    EXPECT_NEAR(g.x(), (terrain.HeightAt(x + h, y) - terrain.HeightAt(x, y)) / h, 1e-4);
    EXPECT_NEAR(g.y(), (terrain.HeightAt(x, y + h) - terrain.HeightAt(x, y)) / h, 1e-4);
    const Eigen::Vector3d n = terrain.NormalAt(x, y);
    EXPECT_NEAR(n.norm(), 1.0, 1e-12);
    EXPECT_GT(n.z(), 0.0);
    EXPECT_NEAR(n.x() / n.z(), -g.x(), 1e-9);
    EXPECT_NEAR(n.y() / n.z(), -g.y(), 1e-9);
    const Eigen::Vector3d smooth = terrain.SmoothNormalAt(x, y);
    EXPECT_NEAR(smooth.norm(), 1.0, 1e-12);
    EXPECT_GT(smooth.z(), 0.0);
  }
  // Outside the grid the height is constant along the clamped axis.
  const double x_out = terrain.max_xy().x() + 1.0;
  EXPECT_EQ(terrain.GradientAt(x_out, 0.3).x(), 0.0);
}

TEST(HeightfieldTest, SmoothNormalIsContinuousAcrossCells) {
  const Heightfield& terrain = SmallWorld().terrain;
  const double border = terrain.origin_xy().x() + 400 * terrain.resolution_m();
  const Eigen::Vector3d left = terrain.SmoothNormalAt(border - 1e-9, 1.234);
  const Eigen::Vector3d right = terrain.SmoothNormalAt(border + 1e-9, 1.234);
  EXPECT_LT((left - right).norm(), 1e-6);
}

// Reference crossing: dense 0.5 mm steps along the ray, then bisection.
bool BruteForceRaycast(const Heightfield& terrain, const Eigen::Vector3d& origin,
                       const Eigen::Vector3d& direction, double max_range_m, double* range_m) {
  const auto clearance = [&](double t) {
    const Eigen::Vector3d p = origin + t * direction;
    return p.z() - terrain.HeightAt(p.x(), p.y());
  };
  const double step = 5e-4;
  double previous = 0.0;
  for (double t = step; t <= max_range_m; t += step) {
    const Eigen::Vector3d p = origin + t * direction;
    if (!terrain.Contains(p.x(), p.y())) return false;
    if (clearance(t) <= 0.0) {
      double low = previous;
      double high = t;
      for (int i = 0; i < 60; ++i) {
        const double mid = 0.5 * (low + high);
        (clearance(mid) > 0.0 ? low : high) = mid;
      }
      *range_m = high;
      return true;
    }
    previous = t;
  }
  return false;
}

TEST(HeightfieldTest, RaycastAgreesWithDenseSampling) {
  const World& world = SmallWorld();
  const Heightfield& terrain = world.terrain;
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int hits = 0;
  int hits_on_rocks = 0;
  for (int i = 0; i < 120; ++i) {
    Eigen::Vector3d origin;
    // Every fourth ray starts next to a rock so that rock flanks get hit too.
    if (i % 4 == 0 && !world.rocks.empty()) {
      const Rock& rock = world.rocks[static_cast<std::size_t>(i / 4) % world.rocks.size()];
      const double angle = 6.283185307179586 * unit(rng);
      origin.head<2>() = rock.center_xy + (RockOuterRadius(rock) + 0.5) *
                                              Eigen::Vector2d(std::cos(angle), std::sin(angle));
    } else {
      origin.head<2>() = Eigen::Vector2d(-15.0 + 30.0 * unit(rng), -15.0 + 30.0 * unit(rng));
    }
    origin.z() = terrain.HeightAt(origin.x(), origin.y()) + 0.2 + 1.5 * unit(rng);
    if (i % 4 == 0 && !world.rocks.empty()) {
      // Low enough to hit the rock's flank.
      origin.z() = terrain.HeightAt(origin.x(), origin.y()) + 0.02 + 0.06 * unit(rng);
    }
    const double azimuth = 6.283185307179586 * unit(rng);
    const double elevation = -(0.01 + 0.9 * unit(rng));
    Eigen::Vector3d direction(std::cos(elevation) * std::cos(azimuth),
                              std::cos(elevation) * std::sin(azimuth), std::sin(elevation));
    if (i % 4 == 0 && !world.rocks.empty()) {
      // Aim at the rock, slightly downwards.
      const Rock& rock = world.rocks[static_cast<std::size_t>(i / 4) % world.rocks.size()];
      direction.head<2>() = (rock.center_xy - origin.head<2>()).normalized();
      direction.z() = -0.05 * unit(rng);
      direction.normalize();
    }
    const double max_range = 15.0;
    double fast = -1.0;
    double reference = -1.0;
    const bool fast_hit = terrain.Raycast(origin, direction, max_range, &fast);
    const bool reference_hit = BruteForceRaycast(terrain, origin, direction, max_range, &reference);
    ASSERT_EQ(fast_hit, reference_hit) << "ray " << i;
    if (fast_hit) {
      ++hits;
      EXPECT_NEAR(fast, reference, 1e-3) << "ray " << i;
      const Eigen::Vector3d p = origin + fast * direction;
      EXPECT_NEAR(p.z(), terrain.HeightAt(p.x(), p.y()), 1e-4) << "ray " << i;
      for (const Rock& rock : world.rocks) {
        if (RockBumpHeight(rock, p.x(), p.y()) > 0.02) {
          ++hits_on_rocks;
          break;
        }
      }
    }
  }
  EXPECT_GT(hits, 60);
  EXPECT_GT(hits_on_rocks, 10);
}

TEST(HeightfieldTest, RaycastMissesUpwardAndOutward) {
  const Heightfield& terrain = SmallWorld().terrain;
  double range = 0.0;
  const Eigen::Vector3d above(1.0, 2.0, terrain.max_height_m() + 0.5);
  EXPECT_FALSE(terrain.Raycast(above, Eigen::Vector3d(0.0, 0.0, 1.0), 100.0, &range));
  EXPECT_FALSE(terrain.Raycast(above, Eigen::Vector3d(0.6, 0.0, 0.8), 100.0, &range));
  EXPECT_FALSE(terrain.Raycast(above, Eigen::Vector3d(1.0, 0.0, 0.0), 100.0, &range));
  // From 0.5 m above the ground, rays 45 degrees up clear every 20 degree hill.
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> azimuth(0.0, 6.283185307179586);
  for (int i = 0; i < 50; ++i) {
    const double a = azimuth(rng);
    const Eigen::Vector3d origin(-3.0, 1.0, terrain.HeightAt(-3.0, 1.0) + 0.5);
    const Eigen::Vector3d up(0.7071 * std::cos(a), 0.7071 * std::sin(a), 0.7071);
    EXPECT_FALSE(terrain.Raycast(origin, up.normalized(), 100.0, &range));
  }
  // Straight down hits at the height difference; a short range stops first.
  const Eigen::Vector3d origin(2.0, -3.0, terrain.HeightAt(2.0, -3.0) + 1.25);
  ASSERT_TRUE(terrain.Raycast(origin, -Eigen::Vector3d::UnitZ(), 100.0, &range));
  EXPECT_NEAR(range, 1.25, 1e-6);
  EXPECT_FALSE(terrain.Raycast(origin, -Eigen::Vector3d::UnitZ(), 1.2, &range));
  // Starting below the surface hits at once.
  const Eigen::Vector3d below(2.0, -3.0, terrain.HeightAt(2.0, -3.0) - 0.1);
  ASSERT_TRUE(terrain.Raycast(below, Eigen::Vector3d(1.0, 0.0, 0.0), 10.0, &range));
  EXPECT_EQ(range, 0.0);
  // Rays leaving the grid before reaching the ground miss.
  const Eigen::Vector3d edge(terrain.max_xy().x() - 0.1, 0.0, terrain.max_height_m() + 0.1);
  EXPECT_FALSE(terrain.Raycast(edge, Eigen::Vector3d(0.8, 0.0, -0.6), 100.0, &range));
}

TEST(HeightfieldTest, RaycastEntersFromOutsideTheGrid) {
  const Heightfield& terrain = SmallWorld().terrain;
  const Eigen::Vector3d origin(terrain.origin_xy().x() - 5.0, 0.5, terrain.max_height_m() + 1.0);
  const Eigen::Vector3d direction = Eigen::Vector3d(1.0, 0.0, -0.2).normalized();
  double fast = 0.0;
  double reference = 0.0;
  ASSERT_TRUE(terrain.Raycast(origin, direction, 100.0, &fast));
  // The reference stops outside the grid; start it on the border instead.
  const double t_enter = 5.0 / direction.x();
  ASSERT_TRUE(
      BruteForceRaycast(terrain, origin + t_enter * direction, direction, 100.0, &reference));
  EXPECT_NEAR(fast, t_enter + reference, 1e-3);
}

TEST(HeightfieldTest, RaycastIsFastEnough) {
  const Heightfield& terrain = SmallWorld().terrain;
  std::mt19937_64 rng(8);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const auto start = std::chrono::steady_clock::now();
  int hits = 0;
  const int rays = 2000;
  for (int i = 0; i < rays; ++i) {
    const Eigen::Vector3d origin(0.0, 0.0, terrain.HeightAt(0.0, 0.0) + 0.6);
    const double azimuth = 6.283185307179586 * unit(rng);
    const double elevation = -0.3 * unit(rng);
    const Eigen::Vector3d direction(std::cos(elevation) * std::cos(azimuth),
                                    std::cos(elevation) * std::sin(azimuth), std::sin(elevation));
    double range = 0.0;
    hits += terrain.Raycast(origin, direction, 100.0, &range) ? 1 : 0;
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("%d rays (%d hits) in %.3f s: %.0f rays/s\n", rays, hits, seconds, rays / seconds);
  EXPECT_GT(hits, rays / 2);
  // Thousands per second are enough; generous for sanitizer builds.
  EXPECT_LT(seconds, 10.0);
}

}  // namespace
}  // namespace rover::sim
