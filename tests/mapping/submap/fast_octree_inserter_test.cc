// FastOctreeInserter against stock OctoMap (insertPointCloud and its scan
// update) on analytic depth images, and the per-image update rules.

#include "mapping/submap/fast_octree_inserter.h"

#include <cmath>
#include <iostream>
#include <vector>

#include <gtest/gtest.h>

#include "tests/mapping/submap/submap_test_scene.h"

namespace rover::mapping {
namespace {

using testing::Compare;
using testing::LeafVoxels;
using testing::ReferenceInsert;
using testing::RockyGround;
using testing::Scan;
using testing::ScanOf;
using testing::Scene;
using testing::SnapToVoxelCentres;

octomap::OcTree MakeTree(const SubmapOptions& o = {}) {
  octomap::OcTree tree(o.octree_resolution_m);
  tree.setProbHit(o.prob_hit);
  tree.setProbMiss(o.prob_miss);
  tree.setClampingThresMin(o.clamping_min);
  tree.setClampingThresMax(o.clamping_max);
  return tree;
}

SubmapOptions WithFreeRange(double max_free_range_m) {
  SubmapOptions o;
  o.max_free_range_m = max_free_range_m;
  return o;
}

// Half resolution keeps the stock reference quick; the bench runs 752x480.
const RectifiedStereo kHead = testing::SimulatorHead(2);
const Eigen::Isometry3d kCamera = testing::CameraPose(0.0, 0.0, 0.7, 0.0, 20.0);

// With every endpoint at its voxel's centre, each voxel's rays coincide:
// the fast path, insertPointCloud with discretize = false and with
// discretize = true all give the same tree.
TEST(FastOctreeInserterTest, EqualsStockExactlyWhenEndpointsCoincidePerVoxel) {
  const DepthImage depth = testing::RenderDepth(kHead, kCamera, RockyGround(), 1.0);
  ASSERT_GT(depth.counts().valid, 20000);
  const SubmapOptions options;
  octomap::OcTree fast = MakeTree(options), exact = MakeTree(options), discrete = MakeTree(options);
  const Scan scan = SnapToVoxelCentres(ScanOf(depth, kCamera, 0.0), fast);
  FastOctreeInserter inserter(options);
  inserter.InsertScan(scan.hits, {}, scan.origin, &fast);
  ReferenceInsert(scan, -1.0, /*discretize=*/false, &exact);
  ReferenceInsert(scan, -1.0, /*discretize=*/true, &discrete);

  const auto voxels = LeafVoxels(fast);
  for (const octomap::OcTree* stock : {&exact, &discrete}) {
    const auto a = Compare(voxels, LeafVoxels(*stock));
    EXPECT_GT(a.occupied_a, 1000u);
    EXPECT_GT(a.free_a, 3000u);
    EXPECT_EQ(a.occupied_a, a.occupied_b);
    EXPECT_EQ(a.free_a, a.free_b);
    EXPECT_EQ(a.occupied_jaccard, 1.0);
    EXPECT_EQ(a.free_jaccard, 1.0);
    EXPECT_EQ(a.value_mismatches, 0u);
  }
  EXPECT_EQ(inserter.stats().occupied_keys, voxels.occupied.size());
  EXPECT_EQ(inserter.stats().free_keys, voxels.free.size());
  EXPECT_EQ(inserter.stats().hit_points, scan.hits.size());
  // One ray per endpoint voxel here, far fewer than points.
  EXPECT_EQ(inserter.stats().rays_cast, inserter.stats().occupied_keys);
}

TEST(FastOctreeInserterTest, EqualsStockWithTheFreeRaysOfInfinitePixels) {
  const DepthImage depth = testing::RenderDepth(kHead, kCamera, RockyGround(), 1.0);
  ASSERT_GT(depth.counts().infinite, 5000);
  const SubmapOptions options = WithFreeRange(5.0);
  octomap::OcTree fast = MakeTree(options), stock = MakeTree(options);
  const Scan scan = SnapToVoxelCentres(ScanOf(depth, kCamera, 5.0), fast);
  FastOctreeInserter inserter(options);
  inserter.InsertScan(scan.hits, scan.free_ends, scan.origin, &fast);
  ReferenceInsert(scan, -1.0, /*discretize=*/true, &stock);
  const auto a = Compare(LeafVoxels(fast), LeafVoxels(stock));
  EXPECT_EQ(a.occupied_jaccard, 1.0);
  EXPECT_EQ(a.free_jaccard, 1.0);
  EXPECT_EQ(a.value_mismatches, 0u);
  EXPECT_EQ(inserter.stats().free_points, static_cast<std::size_t>(depth.counts().infinite));

  // From the depth image itself: the same kInfinite rays (no end voxel is
  // updated, as OctoMap's maxrange rays), adding free space beyond the
  // valid ground.
  octomap::OcTree from_image = MakeTree(options), without = MakeTree(options);
  FastOctreeInserter(options).Insert(depth, kCamera, &from_image);
  FastOctreeInserter(WithFreeRange(0.0)).Insert(depth, kCamera, &without);
  const auto with_rays = LeafVoxels(from_image);
  const auto no_rays = LeafVoxels(without);
  EXPECT_EQ(with_rays.occupied, no_rays.occupied);
  EXPECT_GT(with_rays.free.size(), no_rays.free.size() + 1000);
}

TEST(FastOctreeInserterTest, AgreesWithStockInsertPointCloudOnExactPoints) {
  // Stock insertPointCloud(discretize = false) casts a ray to every exact
  // point, the fast path one per ray cell (2 per voxel edge) to the cell's
  // centroid. Occupied voxels are the endpoints' voxels in both: identical.
  // Free voxels differ where a pixel's ray grazes a voxel near the surface
  // that no cell's ray crosses. Measured on this 376x240 frame: free
  // Jaccard 0.991 with 2 cells (0.987 at 752x480 in bench/mapping), 0.976
  // with 1 cell, 0.996 with 4. The bound leaves room for float differences
  // between compilers, not for a change of method.
  const DepthImage depth = testing::RenderDepth(kHead, kCamera, RockyGround(), 1.0);
  octomap::OcTree stock = MakeTree();
  ReferenceInsert(ScanOf(depth, kCamera, 0.0), -1.0, /*discretize=*/false, &stock);
  const auto stock_voxels = LeafVoxels(stock);
  std::vector<double> free_jaccard;
  for (const int cells : {1, 2, 4}) {
    SubmapOptions options = WithFreeRange(0.0);
    options.ray_cells_per_voxel_edge = cells;
    octomap::OcTree fast = MakeTree(options);
    FastOctreeInserter(options).Insert(depth, kCamera, &fast);
    const auto a = Compare(LeafVoxels(fast), stock_voxels);
    std::cout << "cells " << cells << ": occupied " << a.occupied_a << " / " << a.occupied_b
              << ", free " << a.free_a << " / " << a.free_b << ", free Jaccard " << a.free_jaccard
              << "\n";
    EXPECT_EQ(a.occupied_jaccard, 1.0);
    // Every voxel known to both has the same value: one update per image.
    EXPECT_EQ(a.value_mismatches, 0u);
    free_jaccard.push_back(a.free_jaccard);
  }
  EXPECT_GE(free_jaccard[1], 0.98);  // the default, 2 cells
  // More rays per voxel come closer to a ray per pixel.
  EXPECT_LT(free_jaccard[0], free_jaccard[1]);
  EXPECT_LT(free_jaccard[1], free_jaccard[2]);
}

TEST(FastOctreeInserterTest, StaysEqualToStockAlongADriveWithPruning) {
  // Several images into one tree, pruned midway: the path walk must expand
  // pruned nodes and clamp like OctoMap's updateNode.
  const Scene scene = RockyGround();
  const SubmapOptions options = WithFreeRange(3.0);
  octomap::OcTree fast = MakeTree(options), stock = MakeTree(options);
  FastOctreeInserter inserter(options);
  for (int i = 0; i < 8; ++i) {
    const Eigen::Isometry3d T = testing::CameraPose(0.1 * i, 0.02 * i, 0.7, 0.03 * i, 20.0);
    const DepthImage depth = testing::RenderDepth(testing::SimulatorHead(4), T, scene, 1.0);
    const Scan scan = SnapToVoxelCentres(ScanOf(depth, T, 3.0), fast);
    inserter.InsertScan(scan.hits, scan.free_ends, scan.origin, &fast);
    ReferenceInsert(scan, -1.0, true, &stock);
    if (i == 4) {
      fast.prune();
      stock.prune();
    }
  }
  const auto a = Compare(LeafVoxels(fast), LeafVoxels(stock));
  EXPECT_GT(a.occupied_a, 500u);
  EXPECT_EQ(a.occupied_jaccard, 1.0);
  EXPECT_EQ(a.free_jaccard, 1.0);
  EXPECT_EQ(a.value_mismatches, 0u);
  // Inner nodes hold their children's maximum, as after updateInnerOccupancy.
  octomap::OcTree copy(fast);
  copy.updateInnerOccupancy();
  for (auto it = fast.begin_tree(), c = copy.begin_tree(); it != fast.end_tree(); ++it, ++c) {
    ASSERT_EQ(it->getLogOdds(), c->getLogOdds());
  }
}

TEST(FastOctreeInserterTest, AVoxelHitByManyRaysGetsOneHitUpdate) {
  octomap::OcTree tree = MakeTree();
  SubmapOptions options;
  options.ray_cells_per_voxel_edge = 1;
  FastOctreeInserter inserter(options);
  std::vector<Eigen::Vector3d> hits;
  for (int i = 0; i < 500; ++i) {
    // All inside the voxel [1.0, 1.1) x [0, 0.1) x [0, 0.1).
    hits.emplace_back(1.01 + 0.00016 * i, 0.01 + 0.00015 * i, 0.02 + 0.0001 * i);
  }
  inserter.InsertScan(hits, {}, Eigen::Vector3d(0.05, 0.05, 0.05), &tree);
  const octomap::OcTreeNode* node = tree.search(1.05, 0.05, 0.05);
  ASSERT_NE(node, nullptr);
  EXPECT_EQ(node->getLogOdds(), octomap::logodds(0.7));
  EXPECT_EQ(inserter.stats().hit_points, 500u);
  EXPECT_EQ(inserter.stats().rays_cast, 1u);
  EXPECT_EQ(inserter.stats().occupied_keys, 1u);
  // The voxels between camera and endpoint: one miss each.
  EXPECT_EQ(inserter.stats().free_keys, 10u);
  EXPECT_EQ(tree.search(0.55, 0.05, 0.05)->getLogOdds(), octomap::logodds(0.4));

  // With 2 ray cells per edge: the points fill 4 of the voxel's 8 cells,
  // 4 rays, still one update for the voxel.
  octomap::OcTree cells = MakeTree();
  FastOctreeInserter default_inserter(SubmapOptions{});
  default_inserter.InsertScan(hits, {}, Eigen::Vector3d(0.05, 0.05, 0.05), &cells);
  EXPECT_EQ(default_inserter.stats().rays_cast, 4u);
  EXPECT_EQ(default_inserter.stats().occupied_keys, 1u);
  EXPECT_EQ(cells.search(1.05, 0.05, 0.05)->getLogOdds(), octomap::logodds(0.7));
}

TEST(FastOctreeInserterTest, OccupiedWinsOverFreeWithinOneImage) {
  octomap::OcTree tree = MakeTree();
  FastOctreeInserter inserter(SubmapOptions{});
  // The ray to the far point passes through the near point's voxel.
  const std::vector<Eigen::Vector3d> hits = {{3.05, 0.05, 0.05}, {1.05, 0.05, 0.05}};
  inserter.InsertScan(hits, {}, Eigen::Vector3d(0.05, 0.05, 0.05), &tree);
  EXPECT_EQ(tree.search(1.05, 0.05, 0.05)->getLogOdds(), octomap::logodds(0.7));
  EXPECT_EQ(tree.search(3.05, 0.05, 0.05)->getLogOdds(), octomap::logodds(0.7));
  EXPECT_EQ(tree.search(2.05, 0.05, 0.05)->getLogOdds(), octomap::logodds(0.4));
  EXPECT_EQ(inserter.stats().occupied_keys, 2u);
  EXPECT_EQ(inserter.stats().free_keys, 29u);  // x = 0 .. 2.9 without 1.0
}

TEST(FastOctreeInserterTest, RepeatedImagesClampAtTheBounds) {
  octomap::OcTree tree = MakeTree();
  FastOctreeInserter inserter(SubmapOptions{});
  const std::vector<Eigen::Vector3d> hits = {{2.05, 0.05, 0.05}};
  for (int i = 0; i < 10; ++i) {
    inserter.InsertScan(hits, {}, Eigen::Vector3d(0.05, 0.05, 0.05), &tree);
    const float hit = tree.search(2.05, 0.05, 0.05)->getLogOdds();
    const float free = tree.search(1.05, 0.05, 0.05)->getLogOdds();
    EXPECT_LE(hit, tree.getClampingThresMaxLog());
    EXPECT_GE(free, tree.getClampingThresMinLog());
  }
  // 10 x 0.85 > 3.5 and 10 x -0.41 < -2: both at their bound exactly.
  EXPECT_EQ(tree.search(2.05, 0.05, 0.05)->getLogOdds(), octomap::logodds(0.97));
  EXPECT_EQ(tree.search(1.05, 0.05, 0.05)->getLogOdds(), octomap::logodds(0.12));
  // ...and the root holds the maximum below it.
  EXPECT_EQ(tree.getRoot()->getLogOdds(), octomap::logodds(0.97));
}

TEST(FastOctreeInserterTest, InfinitePixelsClearSpaceUpToMaxFreeRangeOnly) {
  Scene sky;
  sky.stereo_range_m = 0.0;  // everything beyond range: zero disparity
  const RectifiedStereo head = testing::SimulatorHead(8);
  const Eigen::Isometry3d T = testing::CameraPose(0.0, 0.0, 0.7, 0.0, -10.0);
  const DepthImage depth = testing::RenderDepth(head, T, sky);
  ASSERT_EQ(depth.counts().infinite, head.width_px * head.height_px);

  octomap::OcTree tree = MakeTree();
  FastOctreeInserter inserter(WithFreeRange(2.0));
  inserter.Insert(depth, T, &tree);
  const auto voxels = LeafVoxels(tree);
  EXPECT_TRUE(voxels.occupied.empty());
  ASSERT_GT(voxels.free.size(), 500u);
  double farthest = 0.0;
  for (auto it = tree.begin_leafs(); it != tree.end_leafs(); ++it) {
    const octomap::point3d c = it.getCoordinate();
    farthest = std::max(farthest, (Eigen::Vector3d(c.x(), c.y(), c.z()) - T.translation()).norm());
  }
  // Free up to 2 m: the last free voxels' centres lie within half a voxel
  // diagonal of the 2 m sphere, none beyond.
  EXPECT_GT(farthest, 1.85);
  EXPECT_LE(farthest, 2.0 + 0.5 * std::sqrt(3.0) * 0.1);

  octomap::OcTree off = MakeTree();
  FastOctreeInserter(WithFreeRange(0.0)).Insert(depth, T, &off);
  EXPECT_EQ(off.size(), 0u);
}

TEST(FastOctreeInserterTest, PointsBeyondMaxRangeBecomeFreeRaysAsInOctoMap) {
  SubmapOptions options;
  options.max_range_m = 2.0;
  const Eigen::Vector3d origin(0.05, 0.05, 0.05);
  // At voxel centres, along a voxel row for the far one: the ray to the
  // exact point (stock) and to its voxel's centre (fast) are the same ray.
  const std::vector<Eigen::Vector3d> hits = {{5.05, 0.05, 0.05}, {1.55, -0.25, 0.05}};
  octomap::OcTree fast = MakeTree(options), stock = MakeTree(options);
  FastOctreeInserter inserter(options);
  inserter.InsertScan(hits, {}, origin, &fast);
  EXPECT_EQ(inserter.stats().hit_points, 1u);
  EXPECT_EQ(inserter.stats().free_points, 1u);
  testing::Scan scan;
  scan.origin = origin;
  scan.hits = hits;
  ReferenceInsert(scan, 2.0, false, &stock);
  const auto a = Compare(LeafVoxels(fast), LeafVoxels(stock));
  EXPECT_EQ(a.occupied_a, 1u);
  EXPECT_EQ(a.occupied_jaccard, 1.0);
  EXPECT_EQ(a.free_jaccard, 1.0);
  EXPECT_EQ(fast.search(5.05, 0.05, 0.05), nullptr);  // never reached
  EXPECT_EQ(fast.search(2.05, 0.05, 0.05), nullptr);  // the maxrange end voxel
  EXPECT_NE(fast.search(1.95, 0.05, 0.05), nullptr);
}

TEST(FastOctreeInserterTest, InvalidAndUncertainPixelsAddNothing) {
  Scene scene = RockyGround();
  scene.invalid_every = 1;
  const RectifiedStereo head = testing::SimulatorHead(8);
  // Pitched 40 deg down, no pixel sees the sky.
  const Eigen::Isometry3d T = testing::CameraPose(0.0, 0.0, 0.7, 0.0, 40.0);
  octomap::OcTree tree = MakeTree();
  FastOctreeInserter inserter(SubmapOptions{});
  inserter.Insert(testing::RenderDepth(head, T, scene), T, &tree);
  EXPECT_EQ(tree.size(), 0u);
  // Every point too uncertain (sigma_z bound below any real error), and no
  // pixel beyond range:
  scene.invalid_every = 0;
  scene.stereo_range_m = 100.0;
  const DepthImage uncertain = testing::RenderDepth(head, T, scene, 1e-6);
  ASSERT_EQ(uncertain.counts().uncertain, head.width_px * head.height_px);
  inserter.Insert(uncertain, T, &tree);
  EXPECT_EQ(tree.size(), 0u);
  EXPECT_EQ(inserter.stats().rays_cast, 0u);
}

TEST(FastOctreeInserterTest, RejectsAnOriginOutsideTheKeyRangeAndANullTree) {
  octomap::OcTree tree = MakeTree();
  FastOctreeInserter inserter(SubmapOptions{});
  const std::vector<Eigen::Vector3d> hits = {{1.0, 0.0, 0.0}};
  EXPECT_THROW(inserter.InsertScan(hits, {}, Eigen::Vector3d(1e5, 0.0, 0.0), &tree),
               std::invalid_argument);
  EXPECT_THROW(inserter.InsertScan(hits, {}, Eigen::Vector3d::Zero(), nullptr),
               std::invalid_argument);
  // A hit outside the range is skipped, not fatal.
  const std::vector<Eigen::Vector3d> far = {{1e5, 0.0, 0.0}, {1.0, 0.0, 0.0}};
  inserter.InsertScan(far, {}, Eigen::Vector3d::Zero(), &tree);
  EXPECT_EQ(inserter.stats().skipped_points, 1u);
  EXPECT_EQ(inserter.stats().occupied_keys, 1u);
}

}  // namespace
}  // namespace rover::mapping
