#include "mapping/compose/octree_merge.h"

#include <cmath>
#include <numbers>
#include <random>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "tests/mapping/compose/compose_test_util.h"

namespace rover::mapping {
namespace {

using testing::FinestVoxels;
using testing::KeyOf;
using testing::KeyTuple;
using testing::LogOdds;
using testing::MakeSubmapTree;
using testing::Pose;
using testing::SetVoxel;

// The composed tree as MapComposer sets it up.
std::unique_ptr<octomap::OcTree> MakeTarget() {
  auto tree = std::make_unique<octomap::OcTree>(testing::kResolutionM);
  tree->setClampingThresMin(0.12);
  tree->setClampingThresMax(0.97);
  return tree;
}

void Merge(const octomap::OcTree& source, const Eigen::Isometry3d& T, octomap::OcTree* target) {
  MergeOctree(source, T, /*lazy_eval=*/true, target);
  target->updateInnerOccupancy();
}

TEST(OctreeMergeTest, OverlappingVoxelsSumLogOddsWithClamping) {
  const float occupied_max = LogOdds(0.97);
  const float hit = LogOdds(0.7);
  const float miss = LogOdds(0.4);
  const Eigen::Vector3d both_clamped(0.05, 0.05, 0.05);
  const Eigen::Vector3d hit_and_miss(0.15, 0.05, 0.05);
  const Eigen::Vector3d miss_and_miss(0.25, 0.05, 0.05);
  const Eigen::Vector3d only_b(0.35, 0.05, 0.05);
  auto a = MakeSubmapTree();
  SetVoxel(a.get(), both_clamped, occupied_max);
  SetVoxel(a.get(), hit_and_miss, hit);
  SetVoxel(a.get(), miss_and_miss, miss);
  auto b = MakeSubmapTree();
  SetVoxel(b.get(), both_clamped, occupied_max);
  SetVoxel(b.get(), hit_and_miss, miss);
  SetVoxel(b.get(), miss_and_miss, miss);
  SetVoxel(b.get(), only_b, hit);

  auto target = MakeTarget();
  Merge(*a, Eigen::Isometry3d::Identity(), target.get());
  Merge(*b, Eigen::Isometry3d::Identity(), target.get());
  const auto voxels = FinestVoxels(*target);
  ASSERT_EQ(voxels.size(), 4u);
  EXPECT_NEAR(voxels.at(KeyOf(*target, both_clamped)), occupied_max, 1e-6);  // not doubled
  EXPECT_NEAR(voxels.at(KeyOf(*target, hit_and_miss)), hit + miss, 1e-6);
  EXPECT_NEAR(voxels.at(KeyOf(*target, miss_and_miss)), 2 * miss, 1e-6);
  EXPECT_NEAR(voxels.at(KeyOf(*target, only_b)), hit, 1e-6);

  // Free evidence piles up to the lower clamp and no further.
  for (int i = 0; i < 6; ++i) Merge(*b, Eigen::Isometry3d::Identity(), target.get());
  EXPECT_NEAR(FinestVoxels(*target).at(KeyOf(*target, miss_and_miss)), LogOdds(0.12), 1e-6);
}

TEST(OctreeMergeTest, TranslatedAndYawedOriginMovesTheVoxelToTheTransformedKey) {
  auto source = MakeSubmapTree();
  const Eigen::Vector3d p_submap(0.25, 0.05, 0.05);
  SetVoxel(source.get(), p_submap, LogOdds(0.7));
  for (const Eigen::Isometry3d& T :
       {Pose(1.0, 2.0, 0.5, std::numbers::pi / 2), Pose(0.33, -0.12, 0.0, 0.0),
        Pose(-3.0, 0.7, 0.0, -std::numbers::pi), Pose(0.02, 0.01, 0.0, 0.2)}) {
    auto target = MakeTarget();
    Merge(*source, T, target.get());
    const auto voxels = FinestVoxels(*target);
    ASSERT_EQ(voxels.size(), 1u);
    EXPECT_EQ(voxels.begin()->first, KeyOf(*target, T * p_submap));
    EXPECT_NEAR(voxels.begin()->second, LogOdds(0.7), 1e-6);
  }
}

TEST(OctreeMergeTest, YawedBlockIsSampledWithoutHolesOrDoubleCounting) {
  // A 2 m x 2 m slab, two voxels thick, under an arbitrary yaw.
  auto source = MakeSubmapTree();
  const float value = LogOdds(0.7);
  for (int i = 0; i < 20; ++i) {
    for (int j = 0; j < 20; ++j) {
      for (int k = 0; k < 2; ++k) {
        SetVoxel(source.get(), Eigen::Vector3d(0.05 + 0.1 * i, 0.05 + 0.1 * j, 0.05 + 0.1 * k),
                 value);
      }
    }
  }
  const Eigen::Isometry3d T = Pose(0.37, -0.21, 0.0, 30.0 * std::numbers::pi / 180.0);
  auto target = MakeTarget();
  Merge(*source, T, target.get());
  const auto voxels = FinestVoxels(*target);

  // Expected: exactly the world voxels whose centre lies in the slab.
  std::map<KeyTuple, float> expected;
  for (int x = -10; x < 40; ++x) {
    for (int y = -10; y < 40; ++y) {
      for (int z = -2; z < 4; ++z) {
        const Eigen::Vector3d centre(0.1 * x + 0.05, 0.1 * y + 0.05, 0.1 * z + 0.05);
        const Eigen::Vector3d q = T.inverse() * centre;
        if (q.x() >= 0 && q.x() < 2.0 && q.y() >= 0 && q.y() < 2.0 && q.z() >= 0 && q.z() < 0.2) {
          expected[KeyOf(*target, centre)] = value;
        }
      }
    }
  }
  EXPECT_EQ(voxels.size(), expected.size());
  for (const auto& [key, log_odds] : voxels) {
    ASSERT_TRUE(expected.count(key));
    EXPECT_NEAR(log_odds, value, 1e-6);  // every voxel sampled once
  }
  // The slab's volume, give or take its rim.
  EXPECT_NEAR(static_cast<double>(voxels.size()), 800.0, 40.0);
}

TEST(OctreeMergeTest, IsolatedOccupiedVoxelMissedBySamplingIsPushedAndFreeIsDropped) {
  // Yawed by 45 deg with its centre near a voxel corner, the voxel's rotated
  // cube contains no world voxel centre.
  const Eigen::Vector3d p_submap(0.05, 0.05, 0.05);
  Eigen::Isometry3d T = Pose(0, 0, 0, std::numbers::pi / 4);
  T.translation() = Eigen::Vector3d(1.01, 1.01, 0.05) - T.linear() * p_submap;

  auto occupied = MakeSubmapTree();
  SetVoxel(occupied.get(), p_submap, LogOdds(0.7));
  auto target = MakeTarget();
  const OctreeMergeStats stats = MergeOctree(*occupied, T, false, target.get());
  EXPECT_EQ(stats.pushed_leaves, 1u);
  const auto voxels = FinestVoxels(*target);
  ASSERT_EQ(voxels.size(), 1u);
  EXPECT_EQ(voxels.begin()->first, KeyOf(*target, Eigen::Vector3d(1.05, 1.05, 0.05)));

  auto free_space = MakeSubmapTree();
  SetVoxel(free_space.get(), p_submap, LogOdds(0.4));
  auto target_free = MakeTarget();
  EXPECT_EQ(MergeOctree(*free_space, T, false, target_free.get()).voxels_updated, 0u);
  EXPECT_EQ(target_free->getNumLeafNodes(), 0u);
}

TEST(OctreeMergeTest, PrunedLeafIsExpandedToAllItsFinestVoxels) {
  // 4 x 4 x 4 voxels aligned to one depth-14 node, pruned into it.
  auto source = MakeSubmapTree();
  const float value = LogOdds(0.4);
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 4; ++j) {
      for (int k = 0; k < 4; ++k) {
        SetVoxel(source.get(), Eigen::Vector3d(0.05 + 0.1 * i, 0.05 + 0.1 * j, 0.05 + 0.1 * k),
                 value);
      }
    }
  }
  source->prune();
  ASSERT_EQ(source->getNumLeafNodes(), 1u);
  ASSERT_EQ(source->begin_leafs().getDepth(), 14u);

  auto target = MakeTarget();
  // Ten voxels along x: no longer aligned to a depth-14 node.
  const Eigen::Isometry3d T = Pose(1.0, 0.0, 0.0, 0.0);
  const OctreeMergeStats stats = MergeOctree(*source, T, true, target.get());
  target->updateInnerOccupancy();
  EXPECT_EQ(stats.voxels_updated, 64u);
  EXPECT_EQ(target->getNumLeafNodes(), 64u);
  std::map<KeyTuple, float> expected;
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 4; ++j) {
      for (int k = 0; k < 4; ++k) {
        expected[KeyOf(*target, Eigen::Vector3d(1.05 + 0.1 * i, 0.05 + 0.1 * j, 0.05 + 0.1 * k))] =
            value;
      }
    }
  }
  const auto voxels = FinestVoxels(*target);
  ASSERT_EQ(voxels.size(), expected.size());
  for (const auto& [key, log_odds] : expected) {
    ASSERT_TRUE(voxels.count(key));
    EXPECT_NEAR(voxels.at(key), log_odds, 1e-6);
  }
}

TEST(OctreeMergeTest, UndoRestoresTheTreeExactly) {
  std::mt19937 rng(7);
  auto base = testing::RandomSubmapTree(&rng, Eigen::Vector3d(0, 0, 0), 3.0);
  auto overlay = testing::RandomSubmapTree(&rng, Eigen::Vector3d(1.0, 0.5, 0), 3.0);
  auto target = MakeTarget();
  Merge(*base, Eigen::Isometry3d::Identity(), target.get());
  target->prune();
  const auto before = FinestVoxels(*target);
  const std::size_t size_before = target->size();

  std::vector<VoxelUndo> undo;
  MergeOctree(*overlay, Pose(0.1, 0.0, 0.0, 0.3), false, target.get(), &undo);
  ASSERT_FALSE(undo.empty());
  ASSERT_NE(FinestVoxels(*target), before);
  UndoMerge(&undo, target.get());
  EXPECT_TRUE(undo.empty());
  EXPECT_EQ(FinestVoxels(*target), before);
  // Nodes created for the overlay are gone, not merely emptied.
  target->prune();
  EXPECT_EQ(target->size(), size_before);
}

TEST(OctreeMergeTest, UndoOnAnEmptyTreeLeavesItEmpty) {
  std::mt19937 rng(8);
  auto overlay = testing::RandomSubmapTree(&rng, Eigen::Vector3d(0, 0, 0), 1.0);
  auto target = MakeTarget();
  std::vector<VoxelUndo> undo;
  MergeOctree(*overlay, Eigen::Isometry3d::Identity(), false, target.get(), &undo);
  UndoMerge(&undo, target.get());
  EXPECT_EQ(target->getRoot(), nullptr);
  EXPECT_EQ(target->size(), 0u);
  EXPECT_EQ(target->search(0.05, 0.05, 0.05), nullptr);
}

TEST(OctreeMergeTest, DeleteVoxelInsidePrunedLeafKeepsItsSiblings) {
  auto tree = MakeTarget();
  for (int i = 0; i < 2; ++i) {
    for (int j = 0; j < 2; ++j) {
      for (int k = 0; k < 2; ++k) {
        SetVoxel(tree.get(), Eigen::Vector3d(0.05 + 0.1 * i, 0.05 + 0.1 * j, 0.05 + 0.1 * k), 1.0f);
      }
    }
  }
  ASSERT_EQ(tree->getNumLeafNodes(), 1u);  // pruned on insertion
  const octomap::OcTreeKey key = tree->coordToKey(0.05, 0.15, 0.05);
  EXPECT_TRUE(DeleteVoxel(key, tree.get()));
  EXPECT_EQ(tree->getNumLeafNodes(), 7u);
  EXPECT_EQ(tree->search(key), nullptr);
  EXPECT_FALSE(DeleteVoxel(key, tree.get()));
}

TEST(OctreeMergeTest, MismatchedResolutionAndHugeLeavesAreRejected) {
  octomap::OcTree coarse(0.2);
  coarse.updateNode(0.1, 0.1, 0.1, true);
  auto target = MakeTarget();
  EXPECT_THROW(MergeOctree(coarse, Eigen::Isometry3d::Identity(), true, target.get()),
               std::invalid_argument);

  // One leaf of 512 voxels per edge: far beyond any submap.
  auto huge = MakeSubmapTree();
  const octomap::OcTreeKey key = huge->coordToKey(0.05, 0.05, 0.05);
  huge->setNodeValue(key, 0.5f);
  for (unsigned depth = 15; depth >= 7; --depth) {
    octomap::OcTreeNode* node = huge->search(key, depth);
    ASSERT_NE(node, nullptr);
    for (unsigned c = 0; c < 8; ++c) {
      if (!huge->nodeChildExists(node, c)) huge->createNodeChild(node, c)->setLogOdds(0.5f);
    }
    ASSERT_TRUE(huge->pruneNode(node));
  }
  ASSERT_EQ(huge->getNumLeafNodes(), 1u);
  ASSERT_EQ(huge->begin_leafs().getDepth(), 7u);
  EXPECT_THROW(CheckLeafSpans(*huge, "huge"), std::invalid_argument);
  EXPECT_THROW(MergeOctree(*huge, Eigen::Isometry3d::Identity(), true, target.get()),
               std::invalid_argument);
}

}  // namespace
}  // namespace rover::mapping
