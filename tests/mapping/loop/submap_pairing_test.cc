// The pairing rules of thesis section 6.1.1 on hand-made footprints:
// overlap of the obstacle boxes enlarged by k relative sigmas (eq. 6.1/6.2),
// successive and unsuitable submaps never paired, the matcher-precision
// filter (eq. 6.3), the ranking (eq. 6.4), each pair handed out once, and
// the relative covariance (approximated, or given by the caller).

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "core/geometry/so3.h"
#include "core/geometry/yaw.h"
#include "mapping/loop/submap_pairing.h"

namespace rover::mapping {
namespace {

using Eigen::Isometry3d;
using Eigen::Vector2d;
using Eigen::Vector3d;

// A 4 x 4 m obstacle box in front of the origin.
Eigen::AlignedBox2d Box() { return Eigen::AlignedBox2d(Vector2d(1.0, -2.0), Vector2d(5.0, 2.0)); }

Matrix6d Cov(double sigma_m, double sigma_yaw_rad = 0.01) {
  Matrix6d c = Matrix6d::Zero();
  c.diagonal() << sigma_m * sigma_m, sigma_m * sigma_m, sigma_m * sigma_m, 1e-6, 1e-6,
      sigma_yaw_rad * sigma_yaw_rad;
  return c;
}

Isometry3d At(double x, double y, double yaw = 0.0) {
  return GravityAlignedTransform(Vector3d(x, y, 0.0), yaw);
}

SubmapPairingOptions NoPrecisionFilter() {
  SubmapPairingOptions o;
  o.pixel_error_px = 0.0;
  return o;
}

TEST(SubmapPairing, OverlapEnlargedByTheRelativeSigmas) {
  SubmapPairingOptions o = NoPrecisionFilter();
  o.overlap_sigma_factor = 2.0;
  SubmapPairing pairing(o);
  // Robot 0: submap 0 certain, submap 5 with sigma 0.5 m; their boxes are
  // shifted by 3.5 m in x: 0.5 x 4 m of true overlap.
  pairing.AddSubmap({0, 0}, true, Box(), At(0, 0), Cov(0.0));
  pairing.AddSubmap({0, 5}, true, Box(), At(3.5, 0), Cov(0.5));
  const SubmapPair p = pairing.Evaluate({0, 0}, {0, 5});
  // Same robot: sigma = sqrt(|0.25 - 0|) = 0.5 per axis; eq. 6.1 / 6.2.
  EXPECT_NEAR(p.relative_sigma_m.x(), 0.5, 1e-12);
  EXPECT_NEAR(p.overlap_m2, (0.5 + 2.0 * 0.5) * (4.0 + 2.0 * 0.5), 1e-9);
  EXPECT_NEAR(p.score, 0.125 * p.overlap_m2 + 1.5, 1e-9);
  EXPECT_EQ(pairing.Candidates().size(), 1u);

  // With k = 0 the 0.5 x 4 m overlap stays below 2 m^2.
  o.overlap_sigma_factor = 0.0;
  SubmapPairing strict(o);
  strict.AddSubmap({0, 0}, true, Box(), At(0, 0), Cov(0.0));
  strict.AddSubmap({0, 5}, true, Box(), At(3.5, 0), Cov(0.5));
  EXPECT_NEAR(strict.Evaluate({0, 0}, {0, 5}).overlap_m2, 2.0, 1e-9);
  EXPECT_TRUE(strict.Candidates().empty());
  EXPECT_EQ(strict.Check({0, 0}, {0, 5}), PairVerdict::kSmallOverlap);
  // The same overlap as a free function, at the true placement and enlarged.
  EXPECT_NEAR(ObstacleBoxOverlapM2(Box(), At(0, 0), Box(), At(3.5, 0)), 2.0, 1e-9);
  EXPECT_NEAR(ObstacleBoxOverlapM2(Box(), At(0, 0), Box(), At(3.5, 0), Vector2d(1.0, 0.5)),
              1.5 * 4.5, 1e-9);
  EXPECT_EQ(ObstacleBoxOverlapM2(Eigen::AlignedBox2d(), At(0, 0), Box(), At(0, 0)), 0.0);
}

TEST(SubmapPairing, BoxesFollowTheOriginEstimates) {
  SubmapPairing pairing(NoPrecisionFilter());
  pairing.AddSubmap({0, 0}, true, Box(), At(0, 0), Cov(0.0));
  // Turned by 180 deg at x = 6 m: its box covers x in [1, 5] as well.
  pairing.AddSubmap({0, 2}, true, Box(), At(6, 0, M_PI), Cov(0.3));
  EXPECT_NEAR(pairing.Evaluate({0, 0}, {0, 2}).overlap_m2, (4.0 + 3.0 * 0.3) * (4.0 + 3.0 * 0.3),
              1e-6);
  // Moved far away by a graph update: no overlap, no candidate.
  pairing.UpdateOrigin({0, 2}, At(40, 0, M_PI), Cov(0.3));
  EXPECT_EQ(pairing.Evaluate({0, 0}, {0, 2}).overlap_m2, 0.0);
  EXPECT_FALSE(pairing.Next().has_value());
  pairing.UpdateOrigin({0, 2}, At(6, 0, M_PI), Cov(0.3));
  EXPECT_TRUE(pairing.Next().has_value());
}

TEST(SubmapPairing, NeverSuccessiveNeverUnsuitable) {
  SubmapPairing pairing(NoPrecisionFilter());
  pairing.AddSubmap({0, 0}, true, Box(), At(0, 0), Cov(0.0));
  pairing.AddSubmap({0, 1}, true, Box(), At(0.5, 0), Cov(0.5));
  pairing.AddSubmap({0, 2}, false, Box(), At(0.2, 0), Cov(0.8));
  // Robot 1's submap 1 is not robot 0's successor of submap 0.
  pairing.AddSubmap({1, 1}, true, Box(), At(0.3, 0), Cov(0.5));
  const std::vector<SubmapPair> c = pairing.Candidates();
  ASSERT_EQ(c.size(), 2u);
  for (const SubmapPair& p : c) {
    EXPECT_NE(p.a, (SubmapId{0, 2}));
    EXPECT_NE(p.b, (SubmapId{0, 2}));
    EXPECT_FALSE(p.a == (SubmapId{0, 0}) && p.b == (SubmapId{0, 1}));
  }
  EXPECT_EQ(pairing.suitable_count(), 3);
  EXPECT_EQ(pairing.submap_count(), 4);
  // The verdicts name the rule each left-out pair fails first.
  EXPECT_EQ(pairing.Check({0, 0}, {0, 1}), PairVerdict::kSuccessive);
  EXPECT_EQ(pairing.Check({0, 0}, {0, 2}), PairVerdict::kUnsuitable);
  EXPECT_EQ(pairing.Check({0, 1}, {0, 1}), PairVerdict::kSameSubmap);
  EXPECT_EQ(pairing.Check({0, 0}, {1, 1}), PairVerdict::kCandidate);
  EXPECT_STREQ(PairVerdictName(PairVerdict::kUnsuitable), "unsuitable submap");
}

TEST(SubmapPairing, DropsPairsMoreCertainThanTheMatcher) {
  SubmapPairingOptions o;
  // Eq. 6.3 with the thesis's LRU head: 0.5 px * 16 m^2 / (1080 px * 0.09 m)
  // * sqrt(2) = 0.116 m.
  o.focal_px = 1080.0;
  o.baseline_m = 0.09;
  EXPECT_NEAR(o.MatcherPrecisionM(), 0.5 * 16.0 / (1080.0 * 0.09) * std::sqrt(2.0), 1e-12);
  SubmapPairing pairing(o);
  pairing.AddSubmap({0, 0}, true, Box(), At(0, 0), Cov(0.05));
  pairing.AddSubmap({0, 3}, true, Box(), At(1, 0), Cov(0.1));  // sqrt(0.01 - 0.0025) = 0.087
  pairing.AddSubmap({0, 6}, true, Box(), At(1, 0), Cov(0.3));
  const std::vector<SubmapPair> c = pairing.Candidates();
  for (const SubmapPair& p : c) {
    EXPECT_GE(p.relative_sigma_m.mean(), o.MatcherPrecisionM());
    EXPECT_FALSE(p.a == (SubmapId{0, 0}) && p.b == (SubmapId{0, 3}));
  }
  EXPECT_EQ(c.size(), 2u);
  SubmapPair p;
  EXPECT_EQ(pairing.Check({0, 0}, {0, 3}, &p), PairVerdict::kBelowMatcherPrecision);
  EXPECT_NEAR(p.relative_sigma_m.x(), std::sqrt(0.01 - 0.0025), 1e-12);
}

TEST(SubmapPairing, RanksByScoreAndHandsOutEachPairOnce) {
  SubmapPairing pairing(NoPrecisionFilter());
  pairing.AddSubmap({0, 0}, true, Box(), At(0, 0), Cov(0.0));
  pairing.AddSubmap({0, 4}, true, Box(), At(0, 0), Cov(0.2));    // full overlap, small sigma
  pairing.AddSubmap({0, 8}, true, Box(), At(2, 0), Cov(1.0));    // half overlap, large sigma
  pairing.AddSubmap({0, 12}, true, Box(), At(30, 0), Cov(1.0));  // far away
  std::vector<SubmapPair> order;
  while (auto p = pairing.Next()) order.push_back(*p);
  ASSERT_EQ(order.size(), 3u);
  for (std::size_t i = 1; i < order.size(); ++i) EXPECT_GE(order[i - 1].score, order[i].score);
  for (const SubmapPair& p : order) {
    EXPECT_TRUE(pairing.IsDone(p.a, p.b));
    EXPECT_EQ(pairing.Check(p.a, p.b), PairVerdict::kDone);
  }
  // New estimates do not bring a done pair back.
  pairing.UpdateOrigin({0, 8}, At(1, 0), Cov(1.5));
  EXPECT_FALSE(pairing.Next().has_value());
}

TEST(SubmapPairing, MarkDoneByAnotherMatcher) {
  SubmapPairing pairing(NoPrecisionFilter());
  pairing.AddSubmap({0, 0}, true, Box(), At(0, 0), Cov(0.0));
  pairing.AddSubmap({1, 0}, true, Box(), At(0.5, 0), Cov(0.4));
  pairing.AddSubmap({1, 5}, true, Box(), At(-0.5, 0), Cov(0.4));
  ASSERT_EQ(pairing.Candidates().size(), 3u);
  pairing.MarkDone({1, 0}, {0, 0});  // either order
  EXPECT_TRUE(pairing.IsDone({0, 0}, {1, 0}));
  int handed = 0;
  while (auto p = pairing.Next()) {
    EXPECT_FALSE(p->a == (SubmapId{0, 0}) && p->b == (SubmapId{1, 0}));
    ++handed;
  }
  EXPECT_EQ(handed, 2);
}

TEST(SubmapPairing, RelativeUncertaintyApproximationPerRobot) {
  SubmapPairing pairing(NoPrecisionFilter());
  pairing.AddSubmap({0, 0}, true, Box(), At(0, 0), Cov(0.3, 0.02));
  pairing.AddSubmap({0, 7}, true, Box(), At(1, 0, M_PI / 2), Cov(0.5, 0.05));
  pairing.AddSubmap({1, 0}, true, Box(), At(1, 0), Cov(0.4, 0.03));
  // One robot: the thesis's sqrt(|var_a - var_b|); two robots: the sum.
  const SubmapPair same = pairing.Evaluate({0, 0}, {0, 7});
  EXPECT_NEAR(same.relative_sigma_m.x(), 0.4, 1e-12);
  EXPECT_NEAR(std::sqrt(same.prior.covariance(5, 5)), std::sqrt(0.05 * 0.05 - 0.02 * 0.02), 1e-12);
  const SubmapPair other = pairing.Evaluate({0, 0}, {1, 0});
  EXPECT_NEAR(other.relative_sigma_m.x(), 0.5, 1e-12);
  // The prior is T_a_b from the estimates, its covariance in frame a.
  const SubmapPair turned = pairing.Evaluate({0, 7}, {0, 0});
  EXPECT_LT(
      (turned.prior.T_a_b.matrix() - (At(1, 0, M_PI / 2).inverse() * At(0, 0)).matrix()).norm(),
      1e-12);
}

TEST(SubmapPairing, GivenRelativeCovarianceIsUsedInEitherOrder) {
  SubmapPairing pairing(NoPrecisionFilter());
  const Isometry3d T_wa = At(0, 0, 0.3);
  const Isometry3d T_wb = At(2, 1, 1.2);
  pairing.AddSubmap({0, 0}, true, Box(), T_wa, Cov(0.1));
  pairing.AddSubmap({0, 9}, true, Box(), T_wb, Cov(0.1));
  Matrix6d given = Matrix6d::Zero();
  given.diagonal() << 0.04, 0.09, 0.01, 1e-4, 1e-4, 0.0025;
  given(0, 5) = given(5, 0) = 0.004;
  pairing.SetRelativeCovariance({0, 0}, {0, 9}, given);
  EXPECT_LT((pairing.Evaluate({0, 0}, {0, 9}).prior.covariance - given).norm(), 1e-15);

  // Asked the other way round: the covariance of T_b_a, to first order.
  // Check against finite differences of the inversion.
  const Isometry3d T_ab = T_wa.inverse() * T_wb;
  const auto perturb = [&](const Eigen::Matrix<double, 6, 1>& d) {
    Isometry3d T = T_ab;
    T.translation() += d.head<3>();
    T.linear() = T_ab.linear() * ExpSO3(d.tail<3>());
    const Isometry3d inv = T.inverse();
    const Isometry3d inv0 = T_ab.inverse();
    Eigen::Matrix<double, 6, 1> out;
    out.head<3>() = inv.translation() - inv0.translation();
    out.tail<3>() = LogSO3(inv0.linear().transpose() * inv.linear());
    return out;
  };
  Matrix6d J;
  for (int i = 0; i < 6; ++i) {
    Eigen::Matrix<double, 6, 1> d = Eigen::Matrix<double, 6, 1>::Zero();
    d(i) = 1e-7;
    J.col(i) = (perturb(d) - perturb(-d)) / 2e-7;
  }
  const Matrix6d expected = J * given * J.transpose();
  EXPECT_LT((pairing.Evaluate({0, 9}, {0, 0}).prior.covariance - expected).norm(), 1e-8);
  // A graph update invalidates it.
  pairing.UpdateOrigin({0, 9}, T_wb, Cov(0.1));
  EXPECT_GT((pairing.Evaluate({0, 0}, {0, 9}).prior.covariance - given).norm(), 1e-3);
}

TEST(SubmapPairing, BadInputIsNamed) {
  SubmapPairing pairing;
  pairing.AddSubmap({0, 0}, true, Box(), At(0, 0), Cov(0.1));
  EXPECT_THROW(pairing.AddSubmap({0, 0}, true, Box(), At(0, 0), Cov(0.1)), std::invalid_argument);
  Isometry3d bad = At(0, 0);
  bad.translation().x() = NAN;
  try {
    pairing.AddSubmap({0, 1}, true, Box(), bad, Cov(0.1));
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("submap 0/1"), std::string::npos) << e.what();
  }
  Matrix6d nan_cov = Cov(0.1);
  nan_cov(2, 2) = NAN;
  EXPECT_THROW(pairing.UpdateOrigin({0, 0}, At(0, 0), nan_cov), std::invalid_argument);
  try {
    pairing.UpdateOrigin({3, 3}, At(0, 0), Cov(0.1));
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("unknown submap 3/3"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace rover::mapping
