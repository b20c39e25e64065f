// False submap matches for robustness runs: how many, between which origins,
// how wrong, and reproducible.

#include "mapping/slam/false_match_injection.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "core/geometry/yaw.h"

namespace rover::mapping {
namespace {

// Origins every 5 m along a square loop of 20 m sides (16 origins), and a
// graph with a prior, the switches and `matches` true matches.
struct Loop {
  std::map<int64_t, Eigen::Isometry3d> origins;
  std::vector<GraphFactorRecord> factors;
};

Loop MakeLoop(int matches) {
  Loop l;
  for (int64_t k = 0; k < 16; ++k) {
    const int side = static_cast<int>(k / 4);
    const double s = 5.0 * static_cast<double>(k % 4);
    const Eigen::Vector3d corners[4] = {{0, 0, 0}, {20, 0, 0}, {20, 20, 0}, {0, 20, 0}};
    const Eigen::Vector3d dirs[4] = {{1, 0, 0}, {0, 1, 0}, {-1, 0, 0}, {0, -1, 0}};
    l.origins[k] = GravityAlignedTransform(corners[side] + s * dirs[side], side * M_PI / 2.0);
  }
  uint64_t id = 1;
  GraphFactorRecord prior =
      OriginPriorFactor(0, 0, Eigen::Isometry3d::Identity(), 1e-12 * Matrix6d::Identity());
  prior.id = id++;
  l.factors.push_back(prior);
  for (int m = 0; m < matches; ++m) {
    GraphFactorRecord c =
        SubmapMatchFactor(GraphKey::Origin(0, 0), GraphKey::Origin(0, 15 - m),
                          l.origins[0].inverse() * l.origins[15 - m], 0.01 * Matrix6d::Identity());
    c.id = id++;
    l.factors.push_back(c);
  }
  return l;
}

TEST(FalseMatchInjectionTest, ThirtyPercentOfAllMatchesAreFalseNearAndWrong) {
  const Loop l = MakeLoop(7);
  FalseMatchOptions o;
  o.fraction = 0.3;
  const std::vector<GraphFactorRecord> f = MakeFalseSubmapMatches(l.factors, 0, l.origins, o);
  ASSERT_EQ(f.size(), 3u);  // 3 / (3 + 7) = 0.3
  std::set<uint64_t> ids;
  for (const GraphFactorRecord& c : f) {
    EXPECT_EQ(c.kind, FactorKind::kSubmapMatch);
    EXPECT_TRUE(c.robust);
    ASSERT_TRUE(c.b.has_value());
    EXPECT_GE(std::abs(c.b->index - c.a.index), 2) << "never successive frames";
    const Eigen::Isometry3d& a = l.origins.at(c.a.index);
    const Eigen::Isometry3d& b = l.origins.at(c.b->index);
    EXPECT_LE((a.translation() - b.translation()).norm(), o.near_m);
    const Eigen::Isometry3d error = (a.inverse() * b).inverse() * c.T_a_b;
    EXPECT_GE(error.translation().head<2>().norm(), 1.0 - 1e-9);
    EXPECT_LE(error.translation().norm(), o.max_offset_m + 0.1);
    // As confident as the graph's real matches.
    EXPECT_EQ(c.covariance, l.factors[1].covariance);
    EXPECT_GT(c.id, 8u);
    ids.insert(c.id);
  }
  EXPECT_EQ(ids.size(), f.size());
}

TEST(FalseMatchInjectionTest, AGraphWithoutMatchesGetsSomeAndTheSeedDecides) {
  const Loop l = MakeLoop(0);
  FalseMatchOptions o;
  o.fraction = 0.5;
  const std::vector<GraphFactorRecord> a = MakeFalseSubmapMatches(l.factors, 0, l.origins, o);
  EXPECT_EQ(a.size(), 3u);  // a fifth of 16 origins, rounded, as the true count
  const std::vector<GraphFactorRecord> again = MakeFalseSubmapMatches(l.factors, 0, l.origins, o);
  ASSERT_EQ(again.size(), a.size());
  for (std::size_t k = 0; k < a.size(); ++k) {
    EXPECT_EQ(a[k].a, again[k].a);
    EXPECT_TRUE(a[k].T_a_b.isApprox(again[k].T_a_b, 0.0));
  }
  o.seed = 2;
  const std::vector<GraphFactorRecord> other = MakeFalseSubmapMatches(l.factors, 0, l.origins, o);
  ASSERT_EQ(other.size(), a.size());
  EXPECT_FALSE(other[0].T_a_b.isApprox(a[0].T_a_b, 1e-9));
  o.fraction = 0.0;
  EXPECT_TRUE(MakeFalseSubmapMatches(l.factors, 0, l.origins, o).empty());
}

TEST(FalseMatchInjectionTest, InvalidOptionsNameTheKey) {
  FalseMatchOptions o;
  o.fraction = 1.0;
  try {
    o.Validate();
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("FalseMatchOptions.fraction"), std::string::npos);
  }
  o = {};
  o.max_offset_m = 0.5;
  EXPECT_THROW(o.Validate(), std::invalid_argument);
}

}  // namespace
}  // namespace rover::mapping
