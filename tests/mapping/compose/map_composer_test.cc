#include "mapping/compose/map_composer.h"

#include <limits>
#include <numbers>
#include <random>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "tests/mapping/compose/compose_test_util.h"

namespace rover::mapping {
namespace {

using testing::FinestVoxels;
using ::testing::HasSubstr;
using testing::KeyOf;
using testing::LogOdds;
using testing::MakeSubmapTree;
using testing::Pose;
using testing::RandomSubmapTree;
using testing::SetVoxel;

std::shared_ptr<const PointCloud> EmptyCloud() { return std::make_shared<PointCloud>(); }

// One occupied voxel at `p` (submap frame).
std::shared_ptr<octomap::OcTree> SingleVoxelTree(const Eigen::Vector3d& p, float log_odds) {
  auto tree = MakeSubmapTree();
  SetVoxel(tree.get(), p, log_odds);
  return tree;
}

CloudPoint Point(float x, float y, float z, bool obstacle) {
  CloudPoint point;
  point.p_submap_m = Eigen::Vector3f(x, y, z);
  point.obstacle = obstacle;
  return point;
}

TEST(MapComposerTest, OverlappingSubmapsComposeToTheClampedSum) {
  MapComposer composer;
  const Eigen::Vector3d both(0.05, 0.05, 0.05);
  const Eigen::Vector3d mixed(0.15, 0.05, 0.05);
  auto a = MakeSubmapTree();
  SetVoxel(a.get(), both, LogOdds(0.97));
  SetVoxel(a.get(), mixed, LogOdds(0.7));
  // Submap b's frame is 1 m ahead of the world's: it saw the same voxels
  // 1 m behind its origin.
  auto b_shifted = MakeSubmapTree();
  SetVoxel(b_shifted.get(), both - Eigen::Vector3d(1, 0, 0), LogOdds(0.97));
  SetVoxel(b_shifted.get(), mixed - Eigen::Vector3d(1, 0, 0), LogOdds(0.4));
  composer.SetSubmap(1, a, EmptyCloud(), Eigen::Isometry3d::Identity());
  composer.SetSubmap(2, b_shifted, EmptyCloud(), Pose(1, 0, 0, 0));
  const octomap::OcTree& map = composer.Compose();
  const auto voxels = FinestVoxels(map);
  ASSERT_EQ(voxels.size(), 2u);
  EXPECT_NEAR(voxels.at(KeyOf(map, both)), LogOdds(0.97), 1e-6);
  EXPECT_NEAR(voxels.at(KeyOf(map, mixed)), LogOdds(0.7) + LogOdds(0.4), 1e-6);
  EXPECT_TRUE(map.isNodeOccupied(map.search(both.x(), both.y(), both.z())));
}

TEST(MapComposerTest, SubThresholdOriginMovesDoNotRecompose) {
  MapComposer composer;
  const Eigen::Vector3d p(0.05, 0.05, 0.05);
  composer.SetSubmap(1, SingleVoxelTree(p, LogOdds(0.7)), EmptyCloud(),
                     Eigen::Isometry3d::Identity());
  composer.Compose();
  ASSERT_EQ(composer.Stats().recompositions, 1u);

  // 3 cm: below the 5 cm threshold, the cache and its voxel stay.
  composer.SetOrigin(1, Pose(0.03, 0, 0, 0));
  const octomap::OcTree& unchanged = composer.Compose();
  EXPECT_EQ(composer.Stats().recompositions, 1u);
  EXPECT_EQ(FinestVoxels(unchanged).begin()->first, KeyOf(unchanged, p));
  EXPECT_TRUE(composer.Origin(1).isApprox(Pose(0.03, 0, 0, 0)));

  // Another 3 cm: each step is small, but 6 cm from the cached origin.
  composer.SetOrigin(1, Pose(0.06, 0, 0, 0));
  const octomap::OcTree& moved = composer.Compose();
  EXPECT_EQ(composer.Stats().recompositions, 2u);
  EXPECT_EQ(FinestVoxels(moved).begin()->first, KeyOf(moved, p + Eigen::Vector3d(0.06, 0, 0)));

  // Rotations: 0.3 deg stays, 0.6 deg recomposes.
  const double deg = std::numbers::pi / 180.0;
  composer.SetOrigin(1, Pose(0.06, 0, 0, 0.3 * deg));
  composer.Compose();
  EXPECT_EQ(composer.Stats().recompositions, 2u);
  composer.SetOrigin(1, Pose(0.06, 0, 0, 0.6 * deg));
  composer.Compose();
  EXPECT_EQ(composer.Stats().recompositions, 3u);

  // Nothing changed: nothing recomposed.
  composer.Compose();
  EXPECT_EQ(composer.Stats().recompositions, 3u);
}

TEST(MapComposerTest, NewSubmapsAreAppendedAndReplacementsRecompose) {
  std::mt19937 rng(11);
  MapComposer composer;
  MapComposer reference;
  auto add = [&](uint32_t id, const std::shared_ptr<octomap::OcTree>& tree,
                 const Eigen::Isometry3d& T) {
    composer.SetSubmap(id, tree, EmptyCloud(), T);
    reference.SetSubmap(id, tree, EmptyCloud(), T);
  };
  add(10, RandomSubmapTree(&rng, Eigen::Vector3d(0, 0, 0), 2.0), Pose(0, 0, 0, 0.2));
  composer.Compose();
  add(11, RandomSubmapTree(&rng, Eigen::Vector3d(0, 0, 0), 2.0), Pose(0.8, 0.3, 0, 0.9));
  const auto appended = FinestVoxels(composer.Compose());
  EXPECT_EQ(composer.Stats().recompositions, 1u);
  EXPECT_EQ(composer.Stats().appended_submaps, 1u);
  // Appending in id order gives what composing from scratch gives.
  EXPECT_EQ(appended, FinestVoxels(reference.Compose()));

  // An id below the cached ones, and a replacement, rebuild the cache.
  add(5, RandomSubmapTree(&rng, Eigen::Vector3d(0, 0, 0), 2.0), Pose(-0.5, 0, 0, 0));
  composer.Compose();
  EXPECT_EQ(composer.Stats().recompositions, 2u);
  add(11, SingleVoxelTree(Eigen::Vector3d(0.05, 0.05, 0.05), LogOdds(0.97)), Pose(9, 9, 0, 0));
  const auto replaced = FinestVoxels(composer.Compose());
  EXPECT_EQ(composer.Stats().recompositions, 3u);
  EXPECT_EQ(composer.Stats().submaps, 3u);
  EXPECT_EQ(replaced, FinestVoxels(reference.Compose()));
}

TEST(MapComposerTest, MergeAndReleaseComposesAsAllAtOnceWithoutTheData) {
  std::mt19937 rng(17);
  MapComposer streamed;
  MapComposer reference;
  std::weak_ptr<const octomap::OcTree> first_tree;
  for (uint32_t id = 0; id < 6; ++id) {
    const auto tree = RandomSubmapTree(&rng, Eigen::Vector3d(0, 0, 0), 1.5);
    auto cloud = std::make_shared<PointCloud>();
    cloud->push_back(Point(0.1f * static_cast<float>(id), 0.0f, 0.2f, id % 2 == 0));
    const Eigen::Isometry3d T = Pose(0.4 * id, 0.1 * id, 0, 0.3 * id);
    reference.SetSubmap(id, tree, cloud, T);
    streamed.SetSubmap(id, tree, cloud, T);
    if (id == 0) first_tree = tree;
    if (id % 2 == 1) streamed.MergeAndRelease();  // two at a time
  }
  // The composer holds nothing of the released submaps but their origins:
  // only the reference composer still holds the first tree.
  EXPECT_EQ(first_tree.use_count(), 1);
  EXPECT_EQ(streamed.Stats().released_submaps, 6u);
  EXPECT_EQ(streamed.Stats().submaps, 6u);
  EXPECT_TRUE(streamed.Origin(5).isApprox(Pose(2.0, 0.5, 0, 1.5)));
  EXPECT_EQ(FinestVoxels(streamed.Compose()), FinestVoxels(reference.Compose()));
  const PointCloud a = streamed.ComposedCloud();
  const PointCloud b = reference.ComposedCloud();
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].p_submap_m, b[i].p_submap_m);
    EXPECT_EQ(a[i].obstacle, b[i].obstacle);
  }

  // A released submap cannot be merged again: small moves are fine, a move
  // that would rebuild, or an id that would, is refused naming the id.
  streamed.SetOrigin(2, Pose(0.81, 0.2, 0, 0.6));
  try {
    streamed.SetOrigin(2, Pose(3.0, 0.2, 0, 0.6));
    ADD_FAILURE() << "moving a released submap was accepted";
  } catch (const std::logic_error& e) {
    EXPECT_NE(std::string(e.what()).find("submap id 2"), std::string::npos) << e.what();
  }
  EXPECT_THROW(streamed.SetSubmap(3, SingleVoxelTree(Eigen::Vector3d(0.05, 0.05, 0.05), 1.0f),
                                  EmptyCloud(), Pose(0, 0, 0, 0)),
               std::logic_error);
  // A new id above them still appends.
  streamed.SetSubmap(6, SingleVoxelTree(Eigen::Vector3d(0.05, 0.05, 0.05), LogOdds(0.97)),
                     EmptyCloud(), Pose(20, 0, 0, 0));
  const octomap::OcTree& more = streamed.Compose();
  EXPECT_NE(more.search(20.05, 0.05, 0.05), nullptr);
}

TEST(MapComposerTest, CurrentSubmapIsMergedFreshAndNeverCached) {
  std::mt19937 rng(3);
  auto finished = RandomSubmapTree(&rng, Eigen::Vector3d(0, 0, 0), 3.0);
  MapComposer composer;
  composer.SetSubmap(1, finished, EmptyCloud(), Pose(0.2, 0.1, 0, 0.4));
  const auto finished_only = FinestVoxels(composer.Compose());

  for (int round = 0; round < 3; ++round) {
    // A different current submap each time, overlapping the finished one.
    auto current_tree =
        RandomSubmapTree(&rng, Eigen::Vector3d(0.5 * round, 0.3, 0), 2.0 + 0.5 * round);
    const Eigen::Isometry3d T_current = Pose(1.0, 0.2 * round, 0.0, 0.3 * round);
    CurrentSubmap current;
    current.octree = current_tree.get();
    current.T_world_submap = T_current;
    const auto with_current = FinestVoxels(composer.Compose(&current));

    // Same as composing it as a finished submap after the others.
    MapComposer reference;
    reference.SetSubmap(1, finished, EmptyCloud(), Pose(0.2, 0.1, 0, 0.4));
    reference.SetSubmap(2, current_tree, EmptyCloud(), T_current);
    EXPECT_EQ(with_current, FinestVoxels(reference.Compose()));
    EXPECT_NE(with_current, finished_only);
  }
  // Without it, the cache alone: the current submaps never entered it.
  EXPECT_EQ(FinestVoxels(composer.Compose()), finished_only);
  EXPECT_EQ(composer.Stats().recompositions, 1u);
  EXPECT_EQ(composer.Stats().appended_submaps, 0u);
}

TEST(MapComposerTest, CurrentSubmapAloneLeavesNothingBehind) {
  MapComposer composer;
  auto current_tree = SingleVoxelTree(Eigen::Vector3d(0.05, 0.05, 0.05), LogOdds(0.7));
  CurrentSubmap current;
  current.octree = current_tree.get();
  EXPECT_EQ(composer.Compose(&current).getNumLeafNodes(), 1u);
  const octomap::OcTree& empty = composer.Compose();
  EXPECT_EQ(empty.getNumLeafNodes(), 0u);
  EXPECT_EQ(empty.search(0.05, 0.05, 0.05), nullptr);
}

TEST(MapComposerTest, UnknownSubmapIdThrowsNamingIt) {
  MapComposer composer;
  composer.SetSubmap(1, MakeSubmapTree(), EmptyCloud(), Eigen::Isometry3d::Identity());
  try {
    composer.SetOrigin(42, Eigen::Isometry3d::Identity());
    FAIL() << "expected std::out_of_range";
  } catch (const std::out_of_range& e) {
    EXPECT_THAT(e.what(), HasSubstr("42"));
  }
  EXPECT_THROW(composer.Origin(42), std::out_of_range);
  EXPECT_NO_THROW(composer.SetOrigin(1, Pose(1, 0, 0, 0)));
}

TEST(MapComposerTest, SubmapsMustHaveDataAtTheComposedResolution) {
  MapComposer composer;
  EXPECT_THROW(composer.SetSubmap(1, nullptr, EmptyCloud(), Eigen::Isometry3d::Identity()),
               std::invalid_argument);
  EXPECT_THROW(composer.SetSubmap(1, MakeSubmapTree(), nullptr, Eigen::Isometry3d::Identity()),
               std::invalid_argument);
  try {
    composer.SetSubmap(7, std::make_shared<octomap::OcTree>(0.05), EmptyCloud(),
                       Eigen::Isometry3d::Identity());
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), HasSubstr("7"));
    EXPECT_THAT(e.what(), HasSubstr("resolution"));
  }
  EXPECT_FALSE(composer.HasSubmap(7));
  Eigen::Isometry3d nan_origin = Eigen::Isometry3d::Identity();
  nan_origin.translation().x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(composer.SetSubmap(8, MakeSubmapTree(), EmptyCloud(), nan_origin),
               std::invalid_argument);
  composer.SetSubmap(9, MakeSubmapTree(), EmptyCloud(), Eigen::Isometry3d::Identity());
  EXPECT_THROW(composer.SetOrigin(9, nan_origin), std::invalid_argument);
  octomap::OcTree fine(0.05);
  CurrentSubmap current;
  current.octree = &fine;
  EXPECT_THROW(composer.Compose(&current), std::invalid_argument);
}

TEST(MapComposerTest, ComposedCloudIsInTheWorldFrameAndVoxelFiltered) {
  MapComposer composer;  // 5 cm cloud voxels
  auto a = std::make_shared<PointCloud>(
      PointCloud{Point(0.01f, 0.01f, 0.01f, false), Point(0.31f, 0.01f, 0.01f, false)});
  // Submap b's origin is 1 m along x and turned 90 deg: its point (0.01,
  // 0.97) lands at (0.03, 0.01) in the world, in a's first voxel.
  auto b = std::make_shared<PointCloud>(PointCloud{Point(0.01f, 0.97f, 0.01f, true)});
  composer.SetSubmap(1, MakeSubmapTree(), a, Eigen::Isometry3d::Identity());
  composer.SetSubmap(2, MakeSubmapTree(), b, Pose(1.0, 0.0, 0.0, std::numbers::pi / 2));
  const PointCloud cloud = composer.ComposedCloud();
  ASSERT_EQ(cloud.size(), 2u);
  // The merged voxel: mean of its points, an obstacle since one was.
  EXPECT_TRUE(cloud[0].p_submap_m.isApprox(Eigen::Vector3f(0.02f, 0.01f, 0.01f), 1e-5f));
  EXPECT_TRUE(cloud[0].obstacle);
  EXPECT_TRUE(cloud[1].p_submap_m.isApprox(Eigen::Vector3f(0.31f, 0.01f, 0.01f), 1e-5f));
  EXPECT_FALSE(cloud[1].obstacle);

  // The current cloud joins fresh each call and stays out of the cache.
  const PointCloud current_cloud{Point(0.02f, 0.0f, 0.01f, false), Point(5.0f, 0.0f, 0.01f, true)};
  CurrentSubmap current;
  current.cloud = &current_cloud;
  current.T_world_submap = Pose(0.3, 0.02, 0.0, 0.0);
  const PointCloud with_current = composer.ComposedCloud(&current);
  ASSERT_EQ(with_current.size(), 3u);
  EXPECT_TRUE(with_current[1].p_submap_m.isApprox(Eigen::Vector3f(0.315f, 0.015f, 0.01f), 1e-5f));
  EXPECT_TRUE(with_current[2].p_submap_m.isApprox(Eigen::Vector3f(5.3f, 0.02f, 0.01f), 1e-5f));
  EXPECT_TRUE(with_current[2].obstacle);
  EXPECT_EQ(composer.ComposedCloud().size(), 2u);
  EXPECT_EQ(composer.Stats().cloud_recompositions, 1u);

  // Moving an origin far enough rebuilds the cloud at the new place.
  composer.SetOrigin(1, Pose(0.0, 10.0, 0.0, 0.0));
  const PointCloud moved = composer.ComposedCloud();
  EXPECT_EQ(composer.Stats().cloud_recompositions, 2u);
  ASSERT_EQ(moved.size(), 3u);
  EXPECT_TRUE(moved[0].p_submap_m.isApprox(Eigen::Vector3f(0.01f, 10.01f, 0.01f), 1e-5f));
}

TEST(MapComposerTest, ZeroCloudResolutionKeepsEveryPoint) {
  MapComposerOptions options;
  options.cloud_resolution_m = 0.0;
  MapComposer composer(options);
  auto a = std::make_shared<PointCloud>(
      PointCloud{Point(0.01f, 0.01f, 0.01f, false), Point(0.011f, 0.01f, 0.01f, true)});
  composer.SetSubmap(1, MakeSubmapTree(), a, Pose(1, 0, 0, 0));
  const PointCloud current_cloud{Point(0.0f, 0.0f, 0.0f, false)};
  CurrentSubmap current;
  current.cloud = &current_cloud;
  const PointCloud cloud = composer.ComposedCloud(&current);
  ASSERT_EQ(cloud.size(), 3u);
  EXPECT_TRUE(cloud[1].p_submap_m.isApprox(Eigen::Vector3f(1.011f, 0.01f, 0.01f), 1e-6f));
  EXPECT_TRUE(cloud[1].obstacle);
  EXPECT_EQ(composer.ComposedCloud().size(), 2u);
}

TEST(MapComposerTest, StatsDescribeTheComposition) {
  std::mt19937 rng(5);
  MapComposer composer;
  composer.SetSubmap(1, RandomSubmapTree(&rng, Eigen::Vector3d(0, 0, 0), 2.0), EmptyCloud(),
                     Eigen::Isometry3d::Identity());
  const octomap::OcTree& map = composer.Compose();
  const MapComposerStats stats = composer.Stats();
  EXPECT_EQ(stats.submaps, 1u);
  EXPECT_EQ(stats.composed_leaves, map.getNumLeafNodes());
  EXPECT_GT(stats.composed_leaves, 0u);
  EXPECT_GE(stats.octree_memory_bytes, map.memoryUsage());
  EXPECT_GE(stats.last_compose_ms, 0.0);
  EXPECT_EQ(stats.out_of_range_leaves, 0u);
}

TEST(MapComposerOptionsTest, ValidationNamesTheKey) {
  EXPECT_NO_THROW(MapComposerOptions().Validate());
  struct Case {
    std::string key;
    void (*breaks)(MapComposerOptions*);
  };
  const Case cases[] = {
      {"resolution_m", [](MapComposerOptions* o) { o->resolution_m = 0.0; }},
      {"clamping_min_probability",
       [](MapComposerOptions* o) { o->clamping_min_probability = 0.6; }},
      {"clamping_max_probability",
       [](MapComposerOptions* o) { o->clamping_max_probability = 1.0; }},
      {"recompose_translation_m", [](MapComposerOptions* o) { o->recompose_translation_m = -1.0; }},
      {"recompose_rotation_rad", [](MapComposerOptions* o) { o->recompose_rotation_rad = 4.0; }},
      {"cloud_resolution_m", [](MapComposerOptions* o) { o->cloud_resolution_m = -0.05; }},
  };
  for (const Case& c : cases) {
    MapComposerOptions options;
    c.breaks(&options);
    try {
      options.Validate();
      ADD_FAILURE() << c.key << ": expected std::invalid_argument";
    } catch (const std::invalid_argument& e) {
      EXPECT_THAT(e.what(), HasSubstr("MapComposerOptions." + c.key + ":")) << c.key;
    }
    EXPECT_THROW(MapComposer{options}, std::invalid_argument) << c.key;
  }
}

}  // namespace
}  // namespace rover::mapping
