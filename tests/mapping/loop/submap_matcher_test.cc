// The submap matcher on synthetic gravity-aligned submaps (loop_test_scene.h:
// rocks on sloped ground, stereo noise growing with range, the real Submap):
// recovery of the known transform, rejection without overlap and with a
// prior far off, unsuitable flat and wall-only submaps, clear errors for
// NaN input, determinism, concurrency, and the 4D matcher against the 6D
// baseline on a seeded set of pairs.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <Eigen/Eigenvalues>

#include "core/geometry/yaw.h"
#include "mapping/loop/submap_matcher.h"
#include "tests/mapping/loop/loop_test_scene.h"

namespace rover::mapping {
namespace {

using Eigen::Isometry3d;
using testing::ErrorOf;
using testing::LoopWorld;
using testing::PoseError;

constexpr double kDeg = M_PI / 180.0;

struct Built {
  testing::SyntheticSubmap submap;
  std::shared_ptr<const SubmapMatchData> data;
};

Built Build(const LoopWorld& world, const Eigen::Vector2d& start, double yaw, uint64_t seed) {
  Built b;
  b.submap = testing::BuildSubmap(world, testing::StraightDrive(world, start, yaw, 12, 0.5), seed);
  b.data = SubmapMatchData::Build(b.submap.submap->cloud(), b.submap.submap->octree(), {});
  return b;
}

// A prior `offset` (x, y, z in m, then yaw in rad) off the truth, with
// standard deviations sigma_m in x, y, z and sigma_yaw_rad in yaw.
MatchPrior PriorOff(const Isometry3d& truth, const Eigen::Vector4d& offset, double sigma_m,
                    double sigma_yaw_rad) {
  MatchPrior p;
  p.T_a_b = truth * GravityAlignedTransform(offset.head<3>(), offset(3));
  p.covariance = Matrix6d::Zero();
  const double v = sigma_m * sigma_m;
  p.covariance.diagonal() << v, v, v, 1e-4, 1e-4, sigma_yaw_rad * sigma_yaw_rad;
  return p;
}

// A prior off the truth by (0.3, -0.2, 0.05) m and 3 deg, with sigma 0.5 m
// and 5 deg: a loop closure after some drift.
MatchPrior PriorNear(const Isometry3d& truth) {
  return PriorOff(truth, {0.3, -0.2, 0.05, 3.0 * kDeg}, 0.5, 5.0 * kDeg);
}

class SubmapMatcherTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    world_ = new LoopWorld;
    // The rock field of the drives, and a second one 40 m to the left.
    testing::ScatterRocks(-2, 22, -8, 8, 0.25, 1, world_);
    testing::ScatterRocks(-2, 22, 32, 48, 0.25, 2, world_);
    // Four passes through the first field (a revisit each: offsets of up to
    // 1.2 m and 15 deg), one through the second.
    drives_ = new std::vector<Built>;
    drives_->push_back(Build(*world_, {0.0, 0.0}, 0.0, 11));
    drives_->push_back(Build(*world_, {1.0, 0.5}, 0.2, 12));
    drives_->push_back(Build(*world_, {0.5, -0.6}, -0.25, 13));
    drives_->push_back(Build(*world_, {1.2, 0.2}, 0.1, 14));
    drives_->push_back(Build(*world_, {0.0, 40.0}, 0.0, 15));
  }
  static void TearDownTestSuite() {
    delete drives_;
    delete world_;
  }
  static const Built& Drive(int i) { return (*drives_)[static_cast<std::size_t>(i)]; }
  static Isometry3d Truth(int a, int b) {
    return Drive(a).submap.T_world_submap.inverse() * Drive(b).submap.T_world_submap;
  }

  static LoopWorld* world_;
  static std::vector<Built>* drives_;
};

LoopWorld* SubmapMatcherTest::world_ = nullptr;
std::vector<Built>* SubmapMatcherTest::drives_ = nullptr;

TEST_F(SubmapMatcherTest, RecoversTheKnownTransform) {
  for (int i = 0; i < 5; ++i) {
    ASSERT_TRUE(Drive(i).data->suitable()) << i << ": " << Drive(i).data->suitability_reason();
  }
  const SubmapMatcher matcher;
  const Isometry3d truth = Truth(0, 1);
  const SubmapMatchResult r = matcher.Match(*Drive(0).data, *Drive(1).data, PriorNear(truth));
  ASSERT_TRUE(r.accepted) << r.rejection;
  EXPECT_TRUE(r.rejection.empty());
  const PoseError e = ErrorOf(r.T_a_b, truth);
  std::printf(
      "error %.3f m %.2f deg; %zu correspondences, %zu inliers, rmse %.3f m, overlap %.2f, "
      "%.1f ms\n",
      e.translation_m, e.rotation_rad / kDeg, r.correspondences.size(), r.inliers.size(),
      r.icp.rmse_m, r.overlap_ratio, r.timings.total_ms);
  EXPECT_LT(e.translation_m, 0.1);
  EXPECT_LT(e.rotation_rad, 0.5 * kDeg);
  // 4D: roll and pitch exactly zero.
  EXPECT_NEAR(r.T_a_b.linear()(2, 2), 1.0, 1e-12);
  EXPECT_GT(r.inliers.size(), 10u);
  EXPECT_LE(r.inliers.size(), r.correspondences.size());
  EXPECT_GT(r.overlap_ratio, 0.25);
  EXPECT_GT(r.timings.total_ms, 0.0);
  // The covariance: symmetric positive definite, floored, roll and pitch
  // from the option.
  EXPECT_LT((r.covariance - r.covariance.transpose()).norm(), 1e-15);
  EXPECT_GT(Eigen::SelfAdjointEigenSolver<Matrix6d>(r.covariance).eigenvalues().minCoeff(), 0.0);
  const SubmapMatcherOptions& o = matcher.options();
  for (int i = 0; i < 3; ++i) EXPECT_GE(r.covariance(i, i), o.min_sigma_m * o.min_sigma_m);
  EXPECT_GE(r.covariance(5, 5), o.min_sigma_yaw_rad * o.min_sigma_yaw_rad);
  EXPECT_DOUBLE_EQ(r.covariance(3, 3), o.roll_pitch_sigma_rad * o.roll_pitch_sigma_rad);
}

TEST_F(SubmapMatcherTest, RejectsAPairWithoutOverlap) {
  const SubmapMatcher matcher;
  // No prior at all: only the data can reject it.
  for (int a : {0, 1}) {
    const SubmapMatchResult r =
        matcher.Match(*Drive(a).data, *Drive(4).data, MatchPrior::Unbounded());
    EXPECT_FALSE(r.accepted);
    EXPECT_FALSE(r.rejection.empty());
    std::printf(
        "no overlap %d-4: %s inliers %zu/%zu ratio %.3f rmse %.3f overlap %.2f icp corr %d/%d "
        "agreement %d/%d\n",
        a, r.rejection.c_str(), r.inliers.size(), r.correspondences.size(), r.inlier_ratio,
        r.icp.rmse_m, r.overlap_ratio, r.icp.correspondences, r.icp.source_points,
        r.icp.obstacle_points_agreeing, r.icp.obstacle_points_near);
  }
}

TEST_F(SubmapMatcherTest, RejectsAPriorFarOff) {
  const SubmapMatcher matcher;
  const Isometry3d truth = Truth(0, 1);
  MatchPrior prior = PriorNear(truth);
  // 3 m off with sigma 0.3 m: the true alignment lies outside the bounds.
  prior.T_a_b = truth * GravityAlignedTransform({3.0, 0.0, 0.0}, 0.0);
  prior.covariance.diagonal().head<3>().setConstant(0.09);
  const SubmapMatchResult r = matcher.Match(*Drive(0).data, *Drive(1).data, prior);
  EXPECT_FALSE(r.accepted);
  std::printf("prior far off: %s\n", r.rejection.c_str());
  // Whatever it tried stayed inside the bounds: nothing near the truth.
  EXPECT_GT(ErrorOf(r.T_a_b_initial, truth).translation_m, 1.0);
}

TEST_F(SubmapMatcherTest, FlatGroundIsUnsuitableAndAWallOnlyWithTheLineTest) {
  LoopWorld flat;
  const Built plain = Build(flat, {0.0, 0.0}, 0.0, 21);
  EXPECT_EQ(plain.data->suitability(), SubmapSuitability::kTooFewObstaclePoints)
      << plain.data->suitability_reason();
  LoopWorld walled;
  walled.blocks.push_back({{1.0, 1.5, -0.2}, {12.0, 1.8, 0.8}});
  const Built wall = Build(walled, {0.0, 0.0}, 0.0, 22);
  SubmapMatchDataOptions line_test;
  line_test.min_keypoints_off_line = 10;
  const auto strict =
      SubmapMatchData::Build(wall.submap.submap->cloud(), wall.submap.submap->octree(), line_test);
  EXPECT_EQ(strict->suitability(), SubmapSuitability::kKeypointsOnALine)
      << strict->suitability_reason();
  EXPECT_GT(strict->obstacle_point_count(), 100);
  EXPECT_NE(strict->suitability_reason().find("keypoints on a line"), std::string::npos);
  // Never matched.
  const SubmapMatchResult r =
      SubmapMatcher().Match(*Drive(0).data, *strict, MatchPrior::Unbounded());
  EXPECT_FALSE(r.accepted);
  EXPECT_NE(r.rejection.find("submap b unsuitable"), std::string::npos) << r.rejection;
}

// A straight wall on planar ground, driven along twice, the second time
// 1.5 m further on: every keypoint lies along the wall and the whole cloud
// leaves the shift along it free, so the ICP slides. Now that keypoints
// along a line no longer make a submap unsuitable, such a pair must still
// be rejected, and not accepted with the sliding result.
TEST_F(SubmapMatcherTest, KeypointsAlongALineAreNotAcceptedWhenTheCloudSlides) {
  LoopWorld walled;
  walled.slope_x = 0.0;
  walled.slope_y = 0.0;
  walled.blocks.push_back({{-2.0, 1.5, -0.2}, {20.0, 1.8, 0.8}});
  const Built a = Build(walled, {0.0, 0.0}, 0.0, 31);
  const Built b = Build(walled, {1.5, 0.1}, 0.02, 32);
  ASSERT_TRUE(a.data->suitable()) << a.data->suitability_reason();
  ASSERT_TRUE(b.data->suitable()) << b.data->suitability_reason();
  const Isometry3d truth = a.submap.T_world_submap.inverse() * b.submap.T_world_submap;
  for (const MatchPrior& prior : {PriorNear(truth), MatchPrior::Unbounded(truth)}) {
    const SubmapMatchResult r = SubmapMatcher().Match(*a.data, *b.data, prior);
    std::printf("wall (%s): %s, error %.3f m\n", prior.bounded ? "bounded" : "unbounded",
                r.rejection.c_str(), ErrorOf(r.T_a_b, truth).translation_m);
    EXPECT_FALSE(r.accepted);
    EXPECT_FALSE(r.rejection.empty());
    if (!prior.bounded) {
      EXPECT_NE(r.rejection.find("along a line"), std::string::npos) << r.rejection;
    }
  }
}

// A prior as tight as after a short drive: off the truth by (0.08, -0.05)
// m and 0.3 deg, sigma 0.08 m and 0.4 deg.
MatchPrior TightPriorNear(const Isometry3d& truth) {
  return PriorOff(truth, {0.08, -0.05, 0.02, 0.3 * kDeg}, 0.08, 0.4 * kDeg);
}

// Options under which no descriptor corresponds (as between two submaps that
// saw the rocks from opposite sides): only the prior can start the ICP.
SubmapMatcherOptions WithoutKeypointMatches() {
  SubmapMatcherOptions o;
  o.max_descriptor_distance = 1e-9;
  return o;
}

TEST_F(SubmapMatcherTest, ATightPriorStartsTheIcpWhenTheKeypointsFail) {
  const Isometry3d truth = Truth(0, 1);
  const SubmapMatchResult r = SubmapMatcher(WithoutKeypointMatches())
                                  .Match(*Drive(0).data, *Drive(1).data, TightPriorNear(truth));
  ASSERT_TRUE(r.accepted) << r.rejection;
  EXPECT_TRUE(r.from_prior);
  EXPECT_TRUE(r.correspondences.empty());
  const PoseError e = ErrorOf(r.T_a_b, truth);
  std::printf(
      "from the prior: error %.3f m %.2f deg, overlap %.2f, agreement %.2f of %d, rmse %.3f m\n",
      e.translation_m, e.rotation_rad / kDeg, r.overlap_ratio, r.obstacle_agreement,
      r.icp.obstacle_points_near, r.icp.rmse_m);
  // The match targets: within 0.1 m and 0.5 deg (the prior is 0.1 m off).
  EXPECT_LT(e.translation_m, 0.1);
  EXPECT_LT(e.rotation_rad, 0.5 * kDeg);
  EXPECT_GE(r.overlap_ratio, SubmapMatcherOptions{}.prior_icp_min_overlap_ratio);
  EXPECT_GT(Eigen::SelfAdjointEigenSolver<Matrix6d>(r.covariance).eigenvalues().minCoeff(), 0.0);
}

TEST_F(SubmapMatcherTest, ALoosePriorOrTheOptionOffKeepsTheKeypointRejection) {
  const Isometry3d truth = Truth(0, 1);
  // The thesis's prior of a long drive (sigma 0.5 m): too loose for an ICP
  // from the prior.
  SubmapMatchResult r = SubmapMatcher(WithoutKeypointMatches())
                            .Match(*Drive(0).data, *Drive(1).data, PriorNear(truth));
  EXPECT_FALSE(r.accepted);
  EXPECT_FALSE(r.from_prior);
  EXPECT_EQ(r.rejection.find("correspondences"), 0u) << r.rejection;
  // Turned off.
  SubmapMatcherOptions off = WithoutKeypointMatches();
  off.prior_icp_max_sigma_m = 0.0;
  r = SubmapMatcher(off).Match(*Drive(0).data, *Drive(1).data, TightPriorNear(truth));
  EXPECT_FALSE(r.accepted);
  EXPECT_FALSE(r.from_prior);
  // Without bounds there is no prior to start from.
  r = SubmapMatcher(WithoutKeypointMatches())
          .Match(*Drive(0).data, *Drive(1).data, MatchPrior::Unbounded(truth));
  EXPECT_FALSE(r.accepted);
  EXPECT_FALSE(r.from_prior);
}

// An ICP from the prior may only confirm the prior within its bounds: a
// confident prior 0.6 m off the truth (sigma 0.08 m, so bounds of 0.3 m)
// lets the ICP find the true alignment, which lies outside them, and the
// pair is refused rather than followed.
TEST_F(SubmapMatcherTest, AnIcpFromThePriorCannotLeaveItsBounds) {
  const Isometry3d truth = Truth(0, 1);
  MatchPrior prior = TightPriorNear(truth);
  prior.T_a_b = truth * GravityAlignedTransform({0.6, 0.0, 0.0}, 0.0);
  const SubmapMatchResult r =
      SubmapMatcher(WithoutKeypointMatches()).Match(*Drive(0).data, *Drive(1).data, prior);
  EXPECT_FALSE(r.accepted) << "error " << ErrorOf(r.T_a_b, truth).translation_m << " m";
  EXPECT_TRUE(r.from_prior);
  EXPECT_NE(r.rejection.find("aligned from the prior: "), std::string::npos) << r.rejection;
  std::printf("prior 0.6 m off: %s\n", r.rejection.c_str());
}

// The yaw innovation gate, turned on (k = 3): a prior confident in the
// relative heading (sigma 0.1 deg) but 2 deg off the truth. The keypoints
// find the truth, inside the prior's 3 deg bounds, yet 2 deg is beyond 3 of
// the prior's sigmas: refused. A looser prior (1 deg), or the default (gate
// off), accepts the same match.
TEST_F(SubmapMatcherTest, AMatchFarInYawFromAConfidentPriorIsRefusedWithTheGate) {
  const Isometry3d truth = Truth(0, 1);
  SubmapMatcherOptions gated;
  gated.max_yaw_innovation_sigmas = 3.0;
  const SubmapMatcher matcher(gated);
  const MatchPrior confident = PriorOff(truth, {0.05, 0.0, 0.0, 2.0 * kDeg}, 0.1, 0.1 * kDeg);
  SubmapMatchResult r = matcher.Match(*Drive(0).data, *Drive(1).data, confident);
  EXPECT_FALSE(r.accepted);
  EXPECT_NE(r.rejection.find("off the prior's"), std::string::npos) << r.rejection;
  // Refused for its yaw alone: the ICP itself found the truth.
  EXPECT_LT(ErrorOf(r.T_a_b, truth).rotation_rad, 0.5 * kDeg);
  std::printf("confident prior 2 deg off: %s\n", r.rejection.c_str());

  const MatchPrior loose = PriorOff(truth, {0.05, 0.0, 0.0, 2.0 * kDeg}, 0.1, 1.0 * kDeg);
  r = matcher.Match(*Drive(0).data, *Drive(1).data, loose);
  EXPECT_TRUE(r.accepted) << r.rejection;
  r = SubmapMatcher().Match(*Drive(0).data, *Drive(1).data, confident);
  EXPECT_TRUE(r.accepted) << r.rejection;
}

TEST_F(SubmapMatcherTest, NonFiniteInputIsAClearError) {
  PointCloud cloud = Drive(0).submap.submap->cloud();
  cloud[5].p_submap_m.y() = NAN;
  try {
    SubmapMatchData data(cloud, Drive(0).submap.submap->octree(), {});
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("cloud point 5"), std::string::npos) << e.what();
  }
  MatchPrior prior = PriorNear(Truth(0, 1));
  prior.T_a_b.translation().z() = NAN;
  try {
    SubmapMatcher().Match(*Drive(0).data, *Drive(1).data, prior);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("prior.T_a_b"), std::string::npos) << e.what();
  }
  prior = PriorNear(Truth(0, 1));
  prior.covariance(5, 5) = NAN;
  EXPECT_THROW(SubmapMatcher().Match(*Drive(0).data, *Drive(1).data, prior), std::invalid_argument);
}

TEST_F(SubmapMatcherTest, DeterministicAndSafeToRunConcurrently) {
  const SubmapMatcher matcher;
  const MatchPrior prior = PriorNear(Truth(0, 2));
  const SubmapMatchResult first = matcher.Match(*Drive(0).data, *Drive(2).data, prior);
  // Same inputs on two threads at once, and a second matcher with the same
  // options: identical results.
  SubmapMatchResult r1, r2;
  std::thread t1([&] { r1 = matcher.Match(*Drive(0).data, *Drive(2).data, prior); });
  std::thread t2([&] { r2 = SubmapMatcher().Match(*Drive(0).data, *Drive(2).data, prior); });
  t1.join();
  t2.join();
  for (const SubmapMatchResult* r : {&r1, &r2}) {
    EXPECT_EQ(r->accepted, first.accepted);
    EXPECT_EQ(r->rejection, first.rejection);
    EXPECT_EQ(r->T_a_b.matrix(), first.T_a_b.matrix());
    EXPECT_EQ(r->correspondences.size(), first.correspondences.size());
    EXPECT_EQ(r->inliers.size(), first.inliers.size());
    EXPECT_EQ(r->covariance, first.covariance);
  }
  // A different seed may pick other samples but finds the same alignment.
  SubmapMatcherOptions o;
  o.seed = 99;
  const SubmapMatchResult other = SubmapMatcher(o).Match(*Drive(0).data, *Drive(2).data, prior);
  ASSERT_TRUE(first.accepted) << first.rejection;
  ASSERT_TRUE(other.accepted) << other.rejection;
  EXPECT_LT(ErrorOf(other.T_a_b, first.T_a_b).translation_m, 0.05);
}

TEST_F(SubmapMatcherTest, FourDofFindsAtLeastAsManyValidMatchesAsSixDof) {
  int valid[2] = {0, 0};
  int accepted[2] = {0, 0};
  SubmapMatcherOptions o4, o6;
  o6.mode = MatchMode::kSixDof;
  const SubmapMatcher m4(o4), m6(o6);
  for (int a = 0; a < 4; ++a) {
    for (int b = a + 1; b < 4; ++b) {
      const Isometry3d truth = Truth(a, b);
      const MatchPrior prior = PriorNear(truth);
      int k = 0;
      for (const SubmapMatcher* m : {&m4, &m6}) {
        const SubmapMatchResult r = m->Match(*Drive(a).data, *Drive(b).data, prior);
        const PoseError e = ErrorOf(r.T_a_b, truth);
        const PoseError e0 = ErrorOf(r.T_a_b_initial, truth);
        std::printf(
            "%s %d-%d: %s, error %.3f m %.2f deg (initial %.3f m %.2f deg), %.0f ms inliers "
            "%zu/%zu ratio %.3f rmse %.3f overlap %.2f agreement %.2f\n",
            k == 0 ? "4D" : "6D", a, b, r.accepted ? "accepted" : r.rejection.c_str(),
            e.translation_m, e.rotation_rad / kDeg, e0.translation_m, e0.rotation_rad / kDeg,
            r.timings.total_ms, r.inliers.size(), r.correspondences.size(), r.inlier_ratio,
            r.icp.rmse_m, r.overlap_ratio, r.obstacle_agreement);
        accepted[k] += r.accepted;
        valid[k] += r.accepted && e.translation_m < 0.2 && e.rotation_rad < 1.0 * kDeg;
        ++k;
      }
    }
  }
  std::printf("valid 4D %d (accepted %d), 6D %d (accepted %d) of 6\n", valid[0], accepted[0],
              valid[1], accepted[1]);
  EXPECT_GE(valid[0], valid[1]);
  EXPECT_GE(valid[0], 4);
  // Every accepted 4D match is a valid one.
  EXPECT_EQ(valid[0], accepted[0]);
}

}  // namespace
}  // namespace rover::mapping
