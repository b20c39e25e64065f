// The submap matcher (mapping/loop) on one core: one 4D match of two
// synthetic submaps (tests/mapping/loop/loop_test_scene.h: rocks on sloped
// ground, stereo noise, 7 m drives) by stage, the 6D baseline on the same
// pair, and the per-submap precomputation. Then the k-d tree choice, each
// against references in the same run on the same data:
//   descriptors (3 nearest of every keypoint in the other submap):
//     nanoflann k-d tree vs brute force (one matrix product) vs OpenCV FLANN
//     (randomised k-d trees, approximate: its recall is printed);
//   3D points (the ICP's nearest neighbour): nanoflann vs OpenCV FLANN vs a
//     linear scan.
// The library runs no threads of its own; everything here runs on the
// calling thread. Figures are medians over repetitions.

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <functional>
#include <memory>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/flann.hpp>

#include "firmware/mapd/loop_closer.h"
#include "mapping/loop/submap_matcher.h"
#include "tests/mapping/loop/loop_test_scene.h"

namespace {

namespace mapping = rover::mapping;
namespace testing = rover::mapping::testing;
using Clock = std::chrono::steady_clock;

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// Median wall time of `fn` over `reps` runs, ms.
double TimeMs(int reps, const std::function<void()>& fn) {
  std::vector<double> t;
  for (int i = 0; i < reps; ++i) {
    const Clock::time_point t0 = Clock::now();
    fn();
    t.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
  }
  return Median(t);
}

struct Pair {
  testing::SyntheticSubmap a, b;
  Eigen::Isometry3d truth;
};

Pair MakePair() {
  static testing::LoopWorld world = [] {
    testing::LoopWorld w;
    testing::ScatterRocks(-2, 22, -8, 8, 0.25, 1, &w);
    return w;
  }();
  Pair p;
  p.a = testing::BuildSubmap(world, testing::StraightDrive(world, {0.0, 0.0}, 0.0, 14, 0.5), 11);
  p.b = testing::BuildSubmap(world, testing::StraightDrive(world, {1.0, 0.5}, 0.2, 14, 0.5), 12);
  p.truth = p.a.T_world_submap.inverse() * p.b.T_world_submap;
  return p;
}

void MatchTimes(const Pair& pair, int reps) {
  const mapping::SubmapMatchDataOptions data_options;
  const double data_ms = TimeMs(3, [&] {
    mapping::SubmapMatchData d(pair.a.submap->cloud(), pair.a.submap->octree(), data_options);
  });
  const auto a = mapping::SubmapMatchData::Build(pair.a.submap->cloud(), pair.a.submap->octree(),
                                                 data_options);
  const auto b = mapping::SubmapMatchData::Build(pair.b.submap->cloud(), pair.b.submap->octree(),
                                                 data_options);
  std::printf("submaps: %d / %d points, %zu / %zu keypoints; match data %.1f ms per submap\n",
              a->point_count(), b->point_count(), a->keypoints().size(), b->keypoints().size(),
              data_ms);
  mapping::MatchPrior prior;
  prior.T_a_b = pair.truth * rover::GravityAlignedTransform({0.3, -0.2, 0.05}, 0.05);
  prior.covariance = mapping::Matrix6d::Identity() * 0.25;
  prior.covariance(5, 5) = 0.01;
  // The thesis's 4D matcher (the library's defaults), the same with mapd's
  // ICP (its robust weights and normal test), and the 6D baseline.
  struct Variant {
    const char* name;
    mapping::MatchMode mode;
    bool mapd_icp;
  };
  for (const Variant& v : {Variant{"4D", mapping::MatchMode::kFourDof, false},
                           Variant{"4D, mapd's ICP", mapping::MatchMode::kFourDof, true},
                           Variant{"6D", mapping::MatchMode::kSixDof, false}}) {
    mapping::SubmapMatcherOptions o;
    o.mode = v.mode;
    if (v.mapd_icp) o.icp = rover::mapd::LoopCloserOptions{}.matcher.icp;
    const mapping::SubmapMatcher matcher(o);
    std::vector<double> total, corr, hough, ransac, icp;
    mapping::SubmapMatchResult r;
    for (int i = 0; i < reps; ++i) {
      r = matcher.Match(*a, *b, prior);
      total.push_back(r.timings.total_ms);
      corr.push_back(r.timings.correspondences_ms);
      hough.push_back(r.timings.hough_ms);
      ransac.push_back(r.timings.ransac_ms);
      icp.push_back(r.timings.icp_ms);
    }
    const testing::PoseError e = testing::ErrorOf(r.T_a_b, pair.truth);
    std::printf(
        "%s match: %.1f ms (correspondences %.1f, Hough %.1f, RANSAC %.1f, ICP %.1f); %s, error "
        "%.3f m %.2f deg; %zu correspondences, %d clusters, %zu inliers, %d ICP iterations\n",
        v.name, Median(total), Median(corr), Median(hough), Median(ransac), Median(icp),
        r.accepted ? "accepted" : r.rejection.c_str(), e.translation_m,
        e.rotation_rad * 180.0 / M_PI, r.correspondences.size(), r.clusters, r.inliers.size(),
        r.icp.iterations);
  }
}

cv::Mat ToMat(const Eigen::MatrixXf& m) {
  cv::Mat out(static_cast<int>(m.rows()), static_cast<int>(m.cols()), CV_32F);
  for (int r = 0; r < out.rows; ++r) {
    for (int c = 0; c < out.cols; ++c) out.at<float>(r, c) = m(r, c);
  }
  return out;
}

void DescriptorSearch(const Pair& pair, int reps) {
  const auto a =
      mapping::SubmapMatchData::Build(pair.a.submap->cloud(), pair.a.submap->octree(), {});
  const auto b =
      mapping::SubmapMatchData::Build(pair.b.submap->cloud(), pair.b.submap->octree(), {});
  const Eigen::MatrixXf& da = a->descriptors().descriptors();
  const Eigen::MatrixXf& db = b->descriptors().descriptors();
  const mapping::DescriptorIndex kd(db, mapping::DescriptorSearch::kKdTree);
  const mapping::DescriptorIndex brute(db, mapping::DescriptorSearch::kBruteForce);
  std::vector<std::vector<mapping::Neighbour>> exact;
  const double kd_ms = TimeMs(reps, [&] { exact = kd.Nearest(da, 3); });
  const double brute_ms = TimeMs(reps, [&] { brute.Nearest(da, 3); });
  const double kd_build_ms =
      TimeMs(reps, [&] { mapping::DescriptorIndex i(db, mapping::DescriptorSearch::kKdTree); });
  // OpenCV FLANN, 4 randomised trees, 32 checks (its defaults).
  const cv::Mat fa = ToMat(da), fb = ToMat(db);
  std::unique_ptr<cv::flann::Index> flann;
  const double flann_build_ms = TimeMs(reps, [&] {
    flann = std::make_unique<cv::flann::Index>(fb, cv::flann::KDTreeIndexParams(4));
  });
  cv::Mat indices, dists;
  const double flann_ms =
      TimeMs(reps, [&] { flann->knnSearch(fa, indices, dists, 3, cv::flann::SearchParams(32)); });
  int found = 0, total = 0;
  for (int q = 0; q < indices.rows; ++q) {
    for (int k = 0; k < 3; ++k) {
      ++total;
      const int i = indices.at<int>(q, k);
      for (const mapping::Neighbour& n : exact[static_cast<std::size_t>(q)]) {
        found += static_cast<int>(n.index) == i;
      }
    }
  }
  std::printf(
      "descriptor 3-NN, %ld x %ld queries of length %ld: nanoflann %.2f ms (+%.2f build), brute "
      "force %.2f ms (%.2fx nanoflann), OpenCV FLANN %.2f ms (+%.2f build, %.2fx nanoflann, "
      "recall %.3f)\n",
      static_cast<long>(da.rows()), static_cast<long>(db.rows()), static_cast<long>(da.cols()),
      kd_ms, kd_build_ms, brute_ms, brute_ms / kd_ms, flann_ms, flann_build_ms, flann_ms / kd_ms,
      static_cast<double>(found) / total);
}

void PointSearch(const Pair& pair, int reps) {
  const auto a =
      mapping::SubmapMatchData::Build(pair.a.submap->cloud(), pair.a.submap->octree(), {});
  const auto b =
      mapping::SubmapMatchData::Build(pair.b.submap->cloud(), pair.b.submap->octree(), {});
  const std::vector<Eigen::Vector3f>& target = a->cloud().points();
  std::vector<Eigen::Vector3f> queries;
  for (const Eigen::Vector3f& p : b->icp_points()) {
    queries.push_back((pair.truth * p.cast<double>()).cast<float>());
  }
  std::vector<uint32_t> nano(queries.size());
  const double nano_ms = TimeMs(reps, [&] {
    for (std::size_t i = 0; i < queries.size(); ++i) {
      mapping::Neighbour n;
      a->cloud().Nearest(queries[i], 1e9f, &n);
      nano[i] = n.index;
    }
  });
  cv::Mat ft(static_cast<int>(target.size()), 3, CV_32F),
      fq(static_cast<int>(queries.size()), 3, CV_32F);
  for (int i = 0; i < ft.rows; ++i) {
    for (int c = 0; c < 3; ++c) ft.at<float>(i, c) = target[static_cast<std::size_t>(i)][c];
  }
  for (int i = 0; i < fq.rows; ++i) {
    for (int c = 0; c < 3; ++c) fq.at<float>(i, c) = queries[static_cast<std::size_t>(i)][c];
  }
  cv::flann::Index flann(ft, cv::flann::KDTreeIndexParams(1));
  cv::Mat indices, dists;
  const double flann_ms =
      TimeMs(reps, [&] { flann.knnSearch(fq, indices, dists, 1, cv::flann::SearchParams(32)); });
  // The linear scan on a tenth of the queries (it is slow), scaled.
  const std::size_t scan_n = queries.size() / 10;
  int agree = 0;
  const double scan_ms = TimeMs(1,
                                [&] {
                                  for (std::size_t i = 0; i < scan_n; ++i) {
                                    std::size_t best = 0;
                                    float best_d = 1e30f;
                                    for (std::size_t j = 0; j < target.size(); ++j) {
                                      const float d = (target[j] - queries[i]).squaredNorm();
                                      if (d < best_d) best_d = d, best = j;
                                    }
                                    agree += best == nano[i];
                                  }
                                }) *
                         static_cast<double>(queries.size()) / static_cast<double>(scan_n);
  int flann_agree = 0;
  for (int i = 0; i < indices.rows; ++i) {
    flann_agree += indices.at<int>(i, 0) == static_cast<int>(nano[static_cast<std::size_t>(i)]);
  }
  std::printf(
      "3D nearest neighbour, %zu queries in %zu points: nanoflann %.2f ms, OpenCV FLANN %.2f ms "
      "(%.2fx, agrees %.3f), linear scan %.0f ms (%.0fx, agrees %.3f)\n",
      queries.size(), target.size(), nano_ms, flann_ms, flann_ms / nano_ms,
      static_cast<double>(flann_agree) / static_cast<double>(queries.size()), scan_ms,
      scan_ms / nano_ms, static_cast<double>(agree) / static_cast<double>(scan_n));
}

}  // namespace

int main() {
  const Pair pair = MakePair();
  MatchTimes(pair, 5);
  DescriptorSearch(pair, 5);
  PointSearch(pair, 3);
  return 0;
}
