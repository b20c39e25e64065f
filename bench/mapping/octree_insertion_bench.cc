// bench_octree_insertion: one 752x480 depth image into a fresh 10 cm
// OctoMap, FastOctreeInserter against stock octomap::OcTree::insertPointCloud
// on the same points (lazy_eval = false, discretize = false, and also
// discretize = true), interleaved in the same run and reported as medians,
// since the machines are shared and absolute times drift, with the
// agreement of the resulting occupancy (Jaccard of the occupied and of the
// free leaf voxels). Then the ray cells per voxel edge against time and
// agreement, and steady state: a short drive of frames into one growing
// tree, and the whole Submap::Integrate (voxel space and cloud) per frame.
// Targets (issue): >= 5x faster than stock insertPointCloud with the same
// occupancy; >= 15 Hz on one core.
//
// usage: bench_octree_insertion [--reps N] [--frames N] [--stock-every N]

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <memory>
#include <vector>

#include "mapping/submap/fast_octree_inserter.h"
#include "mapping/submap/submap.h"
#include "tests/mapping/submap/submap_test_scene.h"

namespace {

namespace mapping = rover::mapping;
namespace testing = rover::mapping::testing;

double NowMs() {
  return std::chrono::duration<double, std::milli>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

std::unique_ptr<octomap::OcTree> MakeTree(const mapping::SubmapOptions& o) {
  auto tree = std::make_unique<octomap::OcTree>(o.octree_resolution_m);
  tree->setProbHit(o.prob_hit);
  tree->setProbMiss(o.prob_miss);
  tree->setClampingThresMin(o.clamping_min);
  tree->setClampingThresMax(o.clamping_max);
  return tree;
}

// Camera pose of frame i of a short drive: 5 cm per frame forward with a
// slow turn and a little pitch wobble.
Eigen::Isometry3d DrivePose(int i) {
  return testing::CameraPose(0.05 * i, 0.01 * i, 0.7, 0.006 * i, 20.0 + 2.0 * std::sin(0.3 * i));
}

void SingleFrame(int reps) {
  const mapping::RectifiedStereo head = testing::SimulatorHead(1);
  const testing::Scene scene = testing::RockyGround();
  const Eigen::Isometry3d T = testing::CameraPose(0.0, 0.0, 0.7, 0.0, 20.0);
  const mapping::DepthImage depth = testing::RenderDepth(head, T, scene);
  const mapping::DepthImageCounts& c = depth.counts();
  std::printf("depth image %dx%d: valid %d, uncertain %d, infinite %d, invalid %d\n", head.width_px,
              head.height_px, c.valid, c.uncertain, c.infinite, c.invalid);

  mapping::SubmapOptions hits_only;  // the same input as insertPointCloud: kValid hits
  hits_only.max_free_range_m = 0.0;
  const mapping::SubmapOptions full;  // plus free rays of kInfinite pixels (5 m)
  const testing::Scan scan = testing::ScanOf(depth, T, 0.0);
  const testing::Scan scan_full = testing::ScanOf(depth, T, full.max_free_range_m);
  // The stock path gets its octomap::Pointcloud ready-made (not timed).
  const octomap::Pointcloud cloud = testing::ToPointcloud(scan.hits);
  const octomap::point3d origin = testing::ToPoint3d(scan.origin);

  mapping::FastOctreeInserter fast_hits(hits_only), fast_full(full);
  {  // warm-up: the inserter's tables grow to size once
    const auto warm = MakeTree(full);
    fast_hits.Insert(depth, T, warm.get());
    fast_full.Insert(depth, T, warm.get());
  }
  std::vector<double> t_fast, t_fast_full, t_stock, t_stock_discrete, t_stock_full, t_cloud;
  std::unique_ptr<octomap::OcTree> tree_fast, tree_stock, tree_discrete, tree_full, tree_stock_full;
  for (int r = 0; r < reps; ++r) {
    tree_fast = MakeTree(hits_only);
    tree_stock = MakeTree(hits_only);
    tree_discrete = MakeTree(hits_only);
    tree_full = MakeTree(full);
    tree_stock_full = MakeTree(full);
    double t0 = NowMs();
    fast_hits.Insert(depth, T, tree_fast.get());
    t_fast.push_back(NowMs() - t0);
    t0 = NowMs();
    const octomap::Pointcloud prepared = testing::ToPointcloud(testing::ScanOf(depth, T, 0.0).hits);
    t_cloud.push_back(NowMs() - t0);
    if (prepared.size() != cloud.size()) std::abort();  // the same input as `cloud`
    t0 = NowMs();
    tree_stock->insertPointCloud(cloud, origin, -1.0, false, false);
    t_stock.push_back(NowMs() - t0);
    t0 = NowMs();
    tree_discrete->insertPointCloud(cloud, origin, -1.0, false, true);
    t_stock_discrete.push_back(NowMs() - t0);
    t0 = NowMs();
    fast_full.Insert(depth, T, tree_full.get());
    t_fast_full.push_back(NowMs() - t0);
    t0 = NowMs();
    testing::ReferenceInsert(scan_full, -1.0, false, tree_stock_full.get());
    t_stock_full.push_back(NowMs() - t0);
  }
  const double fast = Median(t_fast), stock = Median(t_stock), discrete = Median(t_stock_discrete),
               fast_full_ms = Median(t_fast_full), stock_full = Median(t_stock_full);
  const mapping::FastOctreeInserterStats& s = fast_hits.stats();
  std::printf(
      "fast inserter, per frame: %zu hit points -> %zu rays (one per ray cell holding "
      "endpoints), %zu ray steps, %zu occupied + %zu free voxels updated\n",
      s.hit_points, s.rays_cast, s.ray_keys, s.occupied_keys, s.free_keys);
  std::printf("\nsingle frame into a fresh 10 cm tree (median of %d, interleaved):\n", reps);
  std::printf("  fast inserter (kValid hits)            %8.2f ms   %6.1f Hz  [target >= 15 Hz]\n",
              fast, 1000.0 / fast);
  std::printf(
      "  stock insertPointCloud discretize=false %8.2f ms   speed-up x%.1f  [target >= 5x]\n",
      stock, stock / fast);
  std::printf("  stock insertPointCloud discretize=true  %8.2f ms   speed-up x%.1f\n", discrete,
              discrete / fast);
  std::printf("  fast inserter + kInfinite free rays     %8.2f ms   %6.1f Hz\n", fast_full_ms,
              1000.0 / fast_full_ms);
  std::printf("  stock scan update + kInfinite rays      %8.2f ms   speed-up x%.1f\n", stock_full,
              stock_full / fast_full_ms);
  std::printf(
      "  (stock input, depth image -> octomap::Pointcloud, not in the stock times: %.2f ms;\n"
      "   the fast times include reading the depth image)\n",
      Median(t_cloud));

  const auto voxels_fast = testing::LeafVoxels(*tree_fast);
  const auto a = testing::Compare(voxels_fast, testing::LeafVoxels(*tree_stock));
  const auto b = testing::Compare(voxels_fast, testing::LeafVoxels(*tree_discrete));
  const auto f =
      testing::Compare(testing::LeafVoxels(*tree_full), testing::LeafVoxels(*tree_stock_full));
  std::printf("\noccupancy agreement (Jaccard of full-resolution leaf sets):\n");
  std::printf(
      "  vs discretize=false: occupied %.4f (%zu / %zu), free %.4f (%zu / %zu), "
      "log-odds mismatches %zu\n",
      a.occupied_jaccard, a.occupied_a, a.occupied_b, a.free_jaccard, a.free_a, a.free_b,
      a.value_mismatches);
  std::printf("  vs discretize=true:  occupied %.4f, free %.4f, log-odds mismatches %zu\n",
              b.occupied_jaccard, b.free_jaccard, b.value_mismatches);
  std::printf("  with kInfinite rays vs stock (exact ends): occupied %.4f, free %.4f (%zu / %zu)\n",
              f.occupied_jaccard, f.free_jaccard, f.free_a, f.free_b);
}

// Rays per endpoint voxel: time against agreement with stock (exact rays).
void RayCells(int reps) {
  const mapping::RectifiedStereo head = testing::SimulatorHead(1);
  const Eigen::Isometry3d T = testing::CameraPose(0.0, 0.0, 0.7, 0.0, 20.0);
  const mapping::DepthImage depth = testing::RenderDepth(head, T, testing::RockyGround());
  std::printf("\nray cells per voxel edge (one ray per cell's centroid), single frame:\n");
  for (const double free_range : {0.0, 5.0}) {
    mapping::SubmapOptions o;
    o.max_free_range_m = free_range;
    const auto stock = MakeTree(o);
    testing::ReferenceInsert(testing::ScanOf(depth, T, free_range), -1.0, false, stock.get());
    const auto stock_voxels = testing::LeafVoxels(*stock);
    for (int cells = 1; cells <= 4; ++cells) {
      o.ray_cells_per_voxel_edge = cells;
      mapping::FastOctreeInserter inserter(o);
      std::vector<double> t;
      std::unique_ptr<octomap::OcTree> tree;
      for (int r = 0; r < reps + 1; ++r) {
        tree = MakeTree(o);
        const double t0 = NowMs();
        inserter.Insert(depth, T, tree.get());
        if (r > 0) t.push_back(NowMs() - t0);  // the first one warms up
      }
      const auto a = testing::Compare(testing::LeafVoxels(*tree), stock_voxels);
      std::printf("  %s cells %d: %7.2f ms, %6zu rays, free Jaccard %.4f (%zu / %zu)\n",
                  free_range > 0.0 ? "with kInfinite rays" : "kValid hits only   ", cells,
                  Median(t), inserter.stats().rays_cast, a.free_jaccard, a.free_a, a.free_b);
    }
  }
}

void Drive(int frames, int stock_every) {
  const mapping::RectifiedStereo head = testing::SimulatorHead(1);
  const testing::Scene scene = testing::RockyGround();
  mapping::SubmapOptions hits_only;
  hits_only.max_free_range_m = 0.0;
  const mapping::SubmapOptions full;
  mapping::FastOctreeInserter fast_hits(hits_only), fast_full(full);
  const auto tree_fast = MakeTree(hits_only), tree_stock = MakeTree(hits_only),
             tree_full = MakeTree(full);
  mapping::Submap submap(0, 0, full);
  std::vector<double> t_fast, t_stock, t_full, t_submap;
  for (int i = 0; i < frames; ++i) {
    const Eigen::Isometry3d T = DrivePose(i);
    const mapping::DepthImage depth = testing::RenderDepth(head, T, scene);
    double t0 = NowMs();
    fast_hits.Insert(depth, T, tree_fast.get());
    t_fast.push_back(NowMs() - t0);
    if (i % stock_every == 0) {
      // Stock into its own tree fed every stock_every-th frame (it is slow):
      // the tree is as populated as the fast one at that frame, roughly.
      const testing::Scan scan = testing::ScanOf(depth, T, 0.0);
      const octomap::Pointcloud cloud = testing::ToPointcloud(scan.hits);
      t0 = NowMs();
      tree_stock->insertPointCloud(cloud, testing::ToPoint3d(scan.origin), -1.0, false, false);
      t_stock.push_back(NowMs() - t0);
    }
    t0 = NowMs();
    fast_full.Insert(depth, T, tree_full.get());
    t_full.push_back(NowMs() - t0);
    t0 = NowMs();
    submap.Integrate(depth, {}, T);
    t_submap.push_back(NowMs() - t0);
  }
  const double fast = Median(t_fast), stock = Median(t_stock), fast_full_ms = Median(t_full),
               submap_ms = Median(t_submap);
  std::printf("\nsteady state: %d frames along a %.2f m drive into one tree (median per frame):\n",
              frames, 0.05 * (frames - 1));
  std::printf("  fast inserter (kValid hits)            %8.2f ms   %6.1f Hz  (tree: %zu nodes)\n",
              fast, 1000.0 / fast, tree_fast->size());
  std::printf("  stock insertPointCloud discretize=false %8.2f ms   speed-up x%.1f  (%zu frames)\n",
              stock, stock / fast, t_stock.size());
  std::printf("  fast inserter + kInfinite free rays     %8.2f ms   %6.1f Hz  (tree: %zu nodes)\n",
              fast_full_ms, 1000.0 / fast_full_ms, tree_full->size());
  std::printf(
      "  Submap::Integrate (voxels + cloud)      %8.2f ms   %6.1f Hz  (cloud: %zu points)\n",
      submap_ms, 1000.0 / submap_ms, submap.cloud_size());
  double t0 = NowMs();
  submap.Finish();
  std::printf("  Submap::Finish (prune)                  %8.2f ms   (tree: %zu nodes)\n",
              NowMs() - t0, submap.octree().size());
}

}  // namespace

int main(int argc, char** argv) {
  int reps = 9, frames = 50, stock_every = 5;
  for (int i = 1; i + 1 < argc; i += 2) {
    if (std::strcmp(argv[i], "--reps") == 0) reps = std::max(1, std::atoi(argv[i + 1]));
    if (std::strcmp(argv[i], "--frames") == 0) frames = std::max(1, std::atoi(argv[i + 1]));
    if (std::strcmp(argv[i], "--stock-every") == 0) {
      stock_every = std::max(1, std::atoi(argv[i + 1]));
    }
  }
  SingleFrame(reps);
  RayCells(reps);
  Drive(frames, stock_every);
  return 0;
}
