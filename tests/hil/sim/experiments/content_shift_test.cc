// EstimateContentShift on a synthetic bumpy terrain: clouds sampled on the
// surface and moved by a known shift in their submap frames (two submaps
// with different headings) give that shift back; unshifted clouds give
// (almost) none; on flat ground a horizontal shift cannot be told.

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "core/geometry/yaw.h"
#include "hil/sim/experiments/map_evaluation.h"

namespace rover::sim::experiments {
namespace {

// 40 x 40 m at 5 cm: bumps 1.5 m across, 0.2 m high (slopes up to ~0.4).
Heightfield Terrain(bool flat) {
  const int n = 801;
  std::vector<float> h;
  h.reserve(static_cast<size_t>(n) * n);
  for (int iy = 0; iy < n; ++iy) {
    for (int ix = 0; ix < n; ++ix) {
      const double x = -20.0 + 0.05 * ix, y = -20.0 + 0.05 * iy;
      h.push_back(
          flat ? 0.0f
               : static_cast<float>(0.1 * std::sin(2.1 * x) + 0.1 * std::cos(1.7 * y + 0.3 * x)));
    }
  }
  return Heightfield(n, n, 0.05, Eigen::Vector2d(-20, -20), std::move(h));
}

// Surface points around the submap's origin, in its frame, each moved by
// `shift` (submap frame).
mapping::PointCloud Cloud(const Heightfield& terrain, const Eigen::Isometry3d& T_world_submap,
                          const Eigen::Vector3d& shift, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-5.0, 5.0);
  mapping::PointCloud cloud;
  for (int i = 0; i < 20000; ++i) {
    Eigen::Vector3d p = T_world_submap * Eigen::Vector3d(u(rng), u(rng), 0.0);
    p.z() = terrain.HeightAt(p.x(), p.y());
    mapping::CloudPoint c;
    c.p_submap_m = (T_world_submap.inverse() * p + shift).cast<float>();
    cloud.push_back(c);
  }
  return cloud;
}

ContentShift Estimate(const Heightfield& terrain, const Eigen::Vector3d& shift) {
  const Eigen::Isometry3d T_a = GravityAlignedTransform({-6.0, 2.0, 0.0}, 0.3);
  const Eigen::Isometry3d T_b = GravityAlignedTransform({5.0, -3.0, 0.0}, 2.5);
  const mapping::PointCloud a = Cloud(terrain, T_a, shift, 1);
  const mapping::PointCloud b = Cloud(terrain, T_b, shift, 2);
  return EstimateContentShift(terrain, {{T_a, &a}, {T_b, &b}});
}

TEST(ContentShift, AShiftInEverySubmapsFrameIsRecovered) {
  const Heightfield terrain = Terrain(false);
  const ContentShift s = Estimate(terrain, {0.03, -0.01, 0.005});
  ASSERT_TRUE(s.ok);
  EXPECT_NEAR(s.forward_m, 0.03, 0.004);
  EXPECT_NEAR(s.left_m, -0.01, 0.004);
  EXPECT_NEAR(s.up_m, 0.005, 0.002);
  EXPECT_GT(s.points, 30000u);

  const ContentShift none = Estimate(terrain, Eigen::Vector3d::Zero());
  ASSERT_TRUE(none.ok);
  EXPECT_LT(std::abs(none.forward_m), 0.002);
  EXPECT_LT(std::abs(none.left_m), 0.002);
}

TEST(ContentShift, FlatGroundCannotTell) {
  EXPECT_FALSE(Estimate(Terrain(true), {0.03, 0.0, 0.0}).ok);
  EXPECT_FALSE(EstimateContentShift(Terrain(false), {}).ok);
}

}  // namespace
}  // namespace rover::sim::experiments
