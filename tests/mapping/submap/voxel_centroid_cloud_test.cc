#include "mapping/submap/voxel_centroid_cloud.h"

#include <algorithm>
#include <array>
#include <limits>
#include <random>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

namespace rover::mapping {
namespace {

TEST(VoxelCentroidCloudTest, EachVoxelGivesTheExactMeanOfItsPoints) {
  // 0.5 m voxels and binary fractions: every mean is exact in float.
  VoxelCentroidCloud cloud(0.5);
  EXPECT_TRUE(cloud.Add({0.125f, 0.125f, 0.125f}, false));
  EXPECT_TRUE(cloud.Add({0.375f, 0.25f, 0.25f}, false));
  EXPECT_TRUE(cloud.Add({0.25f, 0.375f, 0.0f}, false));
  EXPECT_TRUE(cloud.Add({-0.25f, 0.25f, 0.25f}, false));  // voxel (-1, 0, 0)
  EXPECT_TRUE(cloud.Add({0.25f, 0.25f, 0.75f}, false));   // voxel (0, 0, 1)
  ASSERT_EQ(cloud.size(), 3u);
  const PointCloud points = cloud.Points();
  ASSERT_EQ(points.size(), 3u);
  // Sorted by voxel index, z first, then y, then x.
  EXPECT_EQ(points[0].p_submap_m, Eigen::Vector3f(-0.25f, 0.25f, 0.25f));
  EXPECT_EQ(points[1].p_submap_m, Eigen::Vector3f(0.25f, 0.25f, 0.125f));
  EXPECT_EQ(points[2].p_submap_m, Eigen::Vector3f(0.25f, 0.25f, 0.75f));
}

TEST(VoxelCentroidCloudTest, AVoxelIsAnObstacleIfAnyOfItsPointsIs) {
  VoxelCentroidCloud cloud(0.05);
  cloud.Add({0.01f, 0.01f, 0.01f}, false);
  cloud.Add({0.02f, 0.02f, 0.02f}, true);
  cloud.Add({0.03f, 0.03f, 0.03f}, false);
  cloud.Add({0.21f, 0.01f, 0.01f}, false);
  cloud.Add({0.22f, 0.01f, 0.01f}, false);
  const PointCloud points = cloud.Points();
  ASSERT_EQ(points.size(), 2u);
  EXPECT_TRUE(points[0].obstacle);
  EXPECT_FALSE(points[1].obstacle);
  EXPECT_NEAR(points[0].p_submap_m.x(), 0.02f, 1e-7f);
}

TEST(VoxelCentroidCloudTest, TheCloudDoesNotDependOnTheOrderOfThePoints) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> coordinate(-3.0f, 3.0f);
  std::vector<std::pair<Eigen::Vector3f, bool>> input;
  for (int i = 0; i < 20000; ++i) {
    input.emplace_back(Eigen::Vector3f(coordinate(rng), coordinate(rng), 0.1f * coordinate(rng)),
                       i % 7 == 0);
  }
  VoxelCentroidCloud a(0.05), b(0.05);
  for (const auto& [p, obstacle] : input) a.Add(p, obstacle);
  std::shuffle(input.begin(), input.end(), rng);
  for (const auto& [p, obstacle] : input) b.Add(p, obstacle);
  const PointCloud pa = a.Points(), pb = b.Points();
  ASSERT_EQ(pa.size(), pb.size());
  ASSERT_GT(pa.size(), 10000u);  // grew well past its first table
  for (std::size_t i = 0; i < pa.size(); ++i) {
    // Sums in double: the order changes at most the last float bit.
    ASSERT_TRUE(pa[i].p_submap_m.isApprox(pb[i].p_submap_m, 1e-6f));
    ASSERT_EQ(pa[i].obstacle, pb[i].obstacle);
    // A centroid lies in its voxel, and the voxels come in (z, y, x) order.
    if (i > 0) {
      const auto index = [](const Eigen::Vector3f& p) {
        const Eigen::Vector3f v = (p.cast<double>() / 0.05).array().floor().cast<float>();
        return std::array<float, 3>{v.z(), v.y(), v.x()};
      };
      ASSERT_LT(index(pa[i - 1].p_submap_m), index(pa[i].p_submap_m));
    }
  }
}

TEST(VoxelCentroidCloudTest, RejectsNonFiniteAndFarPointsAndBadResolutions) {
  VoxelCentroidCloud cloud(0.05);
  EXPECT_FALSE(cloud.Add({std::numeric_limits<float>::quiet_NaN(), 0.0f, 0.0f}, false));
  EXPECT_FALSE(cloud.Add({std::numeric_limits<float>::infinity(), 0.0f, 0.0f}, false));
  EXPECT_FALSE(cloud.Add({1e6f, 0.0f, 0.0f}, false));  // beyond 2^20 voxels
  EXPECT_EQ(cloud.size(), 0u);
  EXPECT_TRUE(cloud.Add({-5e4f, 0.0f, 0.0f}, false));
  cloud.Clear();
  EXPECT_EQ(cloud.size(), 0u);
  EXPECT_TRUE(cloud.Points().empty());
  EXPECT_THROW(VoxelCentroidCloud(0.0), std::invalid_argument);
  EXPECT_THROW(VoxelCentroidCloud(-0.05), std::invalid_argument);
}

}  // namespace
}  // namespace rover::mapping
