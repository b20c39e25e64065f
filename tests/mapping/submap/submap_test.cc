#include "mapping/submap/submap.h"

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "tests/mapping/submap/submap_test_scene.h"

namespace rover::mapping {
namespace {

const RectifiedStereo kHead = testing::SimulatorHead(4);
const Eigen::Isometry3d kCamera = testing::CameraPose(0.0, 0.0, 0.7, 0.0, 20.0);

// Quarter resolution: sigma_z reaches 0.15 m at 1.6 m already; a looser
// bound keeps the rocks (2-4.5 m) valid.
DepthImage Render(const Eigen::Isometry3d& T) {
  return testing::RenderDepth(kHead, T, testing::RockyGround(), 1.0);
}

// Pixels whose point stands more than 5 cm above the ground: the rocks.
std::vector<uint8_t> RockMask(const DepthImage& depth, const Eigen::Isometry3d& T) {
  const testing::Scene scene = testing::RockyGround();
  std::vector<uint8_t> mask(static_cast<std::size_t>(depth.width() * depth.height()), 0);
  for (int v = 0; v < depth.height(); ++v) {
    for (int u = 0; u < depth.width(); ++u) {
      if (depth.state(u, v) != DepthState::kValid) continue;
      const Eigen::Vector3d p = T * depth.point(u, v).cast<double>();
      const bool rock = p.z() - testing::GroundHeight(scene, p.x(), p.y()) > 0.05;
      mask[static_cast<std::size_t>(v * depth.width() + u)] = rock ? 1 : 0;
    }
  }
  return mask;
}

TEST(SubmapTest, IntegrateFillsTheVoxelSpaceAndTheCloud) {
  Submap submap(3, 17, SubmapOptions{});
  EXPECT_EQ(submap.index(), 3u);
  EXPECT_EQ(submap.frame_id(), 17u);
  const DepthImage depth = Render(kCamera);
  const std::vector<uint8_t> mask = RockMask(depth, kCamera);
  submap.Integrate(depth, mask, kCamera);
  EXPECT_EQ(submap.images(), 1);
  EXPECT_GT(submap.last_insertion().occupied_keys, 100u);

  // The near rock's front (centre (2, 0.2, 0.05), radius 0.25) at height
  // 0.25 m: the surface crosses x = 1.86 at y = 0.25.
  const octomap::OcTreeNode* top = submap.octree().search(1.85, 0.25, 0.25);
  ASSERT_NE(top, nullptr);
  EXPECT_TRUE(submap.octree().isNodeOccupied(top));
  // The air between the camera and the ground is free.
  const octomap::OcTreeNode* air = submap.octree().search(0.8, 0.0, 0.3);
  ASSERT_NE(air, nullptr);
  EXPECT_FALSE(submap.octree().isNodeOccupied(air));

  const PointCloud cloud = submap.cloud();
  EXPECT_EQ(cloud.size(), submap.cloud_size());
  const testing::Scene scene = testing::RockyGround();
  std::size_t obstacles = 0;
  for (const CloudPoint& p : cloud) {
    // A centroid 6 cm above the ground has a rock point in its voxel.
    const Eigen::Vector3d c = p.p_submap_m.cast<double>();
    if (c.z() - testing::GroundHeight(scene, c.x(), c.y()) > 0.06) {
      EXPECT_TRUE(p.obstacle);
    }
    if (!p.obstacle) continue;
    ++obstacles;
    // Flagged voxels hold a rock point: their centroid is near a rock.
    double nearest = 1e9;
    for (const testing::Rock& rock : scene.rocks) {
      nearest =
          std::min(nearest, (p.p_submap_m.cast<double>() - rock.centre).norm() - rock.radius_m);
    }
    EXPECT_LT(nearest, 0.1);
  }
  EXPECT_GT(obstacles, 50u);
  EXPECT_LT(obstacles, cloud.size() / 2);

  // Without a mask, nothing is an obstacle.
  Submap plain(0, 0, SubmapOptions{});
  plain.Integrate(depth, {}, kCamera);
  for (const CloudPoint& p : plain.cloud()) ASSERT_FALSE(p.obstacle);
  EXPECT_EQ(plain.cloud_size(), submap.cloud_size());
}

TEST(SubmapTest, TheOctreeUsesTheOptions) {
  SubmapOptions options;
  options.octree_resolution_m = 0.2;
  options.prob_hit = 0.8;
  options.prob_miss = 0.3;
  options.clamping_min = 0.2;
  options.clamping_max = 0.9;
  const Submap submap(0, 0, options);
  EXPECT_DOUBLE_EQ(submap.octree().getResolution(), 0.2);
  EXPECT_NEAR(submap.octree().getProbHit(), 0.8, 1e-6);
  EXPECT_NEAR(submap.octree().getProbMiss(), 0.3, 1e-6);
  EXPECT_NEAR(submap.octree().getClampingThresMin(), 0.2, 1e-6);
  EXPECT_NEAR(submap.octree().getClampingThresMax(), 0.9, 1e-6);
}

TEST(SubmapTest, MaxRangeAlsoBoundsTheCloud) {
  SubmapOptions options;
  options.max_range_m = 2.0;
  Submap submap(0, 0, options);
  const DepthImage depth = Render(kCamera);
  submap.Integrate(depth, {}, kCamera);
  ASSERT_GT(submap.cloud_size(), 100u);
  for (const CloudPoint& p : submap.cloud()) {
    ASSERT_LE((p.p_submap_m.cast<double>() - kCamera.translation()).norm(), 2.0 + 1e-3);
  }
}

TEST(SubmapTest, RejectsAMaskOfTheWrongSize) {
  Submap submap(0, 0, SubmapOptions{});
  const DepthImage depth = Render(kCamera);
  EXPECT_THROW(submap.Integrate(depth, std::vector<uint8_t>(10, 0), kCamera),
               std::invalid_argument);
  EXPECT_EQ(submap.images(), 0);
}

TEST(SubmapTest, FinishPrunesWithoutChangingVoxelsAndFreezes) {
  Submap submap(0, 0, SubmapOptions{});
  for (int i = 0; i < 3; ++i) {
    const Eigen::Isometry3d T = testing::CameraPose(0.2 * i, 0.0, 0.7, 0.0, 20.0);
    submap.Integrate(Render(T), {}, T);
  }
  const auto before = testing::LeafVoxels(submap.octree());
  const std::size_t nodes_before = submap.octree().size();
  submap.Finish();
  EXPECT_TRUE(submap.finished());
  EXPECT_LT(submap.octree().size(), nodes_before);
  const auto after = testing::LeafVoxels(submap.octree());
  EXPECT_EQ(after.occupied, before.occupied);
  EXPECT_EQ(after.free, before.free);
  EXPECT_EQ(after.log_odds, before.log_odds);

  const DepthImage depth = Render(kCamera);
  EXPECT_THROW(submap.Integrate(depth, {}, kCamera), std::logic_error);
  EXPECT_EQ(submap.images(), 3);
}

// One invalid value per key: the message names it.
TEST(SubmapTest, OptionsValidationNamesTheKey) {
  EXPECT_NO_THROW(SubmapOptions{}.Validate());
  const auto expect_key = [](SubmapOptions o, const std::string& key) {
    try {
      o.Validate();
      ADD_FAILURE() << key << " accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_EQ(std::string(e.what()).rfind("SubmapOptions." + key + ": expected ", 0), 0u)
          << e.what();
      EXPECT_NE(std::string(e.what()).find(", got "), std::string::npos) << e.what();
    }
  };
  SubmapOptions o;
  o.octree_resolution_m = 0.0;
  expect_key(o, "octree_resolution_m");
  o = {};
  o.prob_hit = 0.5;
  expect_key(o, "prob_hit");
  o = {};
  o.prob_miss = 0.6;
  expect_key(o, "prob_miss");
  o = {};
  o.clamping_min = 0.0;
  expect_key(o, "clamping_min");
  o = {};
  o.clamping_max = 1.0;
  expect_key(o, "clamping_max");
  o = {};
  o.cloud_resolution_m = -0.05;
  expect_key(o, "cloud_resolution_m");
  o = {};
  o.max_free_range_m = -1.0;
  expect_key(o, "max_free_range_m");
  o = {};
  o.max_range_m = std::numeric_limits<double>::quiet_NaN();
  expect_key(o, "max_range_m");
  o = {};
  o.prob_hit = 0.0;
  EXPECT_THROW(Submap(0, 0, o), std::invalid_argument);
}

}  // namespace
}  // namespace rover::mapping
