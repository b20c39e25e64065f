// The rover graph built from factor records as mapd adds them: a submap
// match that contradicts everything else barely moves the solution (the
// Cauchy loss on c factors), while the same match under least squares drags
// the graph metres away (so the check can fail).

#include <gtest/gtest.h>

#include <cmath>

#include "core/geometry/yaw.h"
#include "mapping/graph/rover_graph.h"
#include "mapping/slam/graph_factor_record.h"

namespace rover::mapping {
namespace {

constexpr int kOrigins = 16;

// Origins every 5 m around a 20 m square; the switches carry a small yaw
// drift (0.5 deg each), two matches close the loop.
std::vector<GraphFactorRecord> SquareLoop(std::vector<Eigen::Isometry3d>* truth) {
  truth->clear();
  for (int k = 0; k < kOrigins; ++k) {
    const int side = k / 4;
    const double s = 5.0 * (k % 4);
    const Eigen::Vector3d corners[4] = {{0, 0, 0}, {20, 0, 0}, {20, 20, 0}, {0, 20, 0}};
    const Eigen::Vector3d dirs[4] = {{1, 0, 0}, {0, 1, 0}, {-1, 0, 0}, {0, -1, 0}};
    truth->push_back(GravityAlignedTransform(corners[side] + s * dirs[side], side * M_PI / 2.0));
  }
  std::vector<GraphFactorRecord> f;
  uint64_t id = 1;
  f.push_back(OriginPriorFactor(0, 0, (*truth)[0], 1e-12 * Matrix6d::Identity()));
  Eigen::Matrix4d switch_cov = Eigen::Matrix4d::Zero();
  switch_cov.diagonal() << 0.01, 0.01, 0.0025, std::pow(1.0 * M_PI / 180.0, 2);
  for (int k = 0; k + 1 < kOrigins; ++k) {
    const Eigen::Isometry3d T = truth->at(static_cast<std::size_t>(k)).inverse() *
                                truth->at(static_cast<std::size_t>(k + 1));
    const double yaw = std::atan2(T.linear()(1, 0), T.linear()(0, 0)) + 0.5 * M_PI / 180.0;
    f.push_back(FrameSwitchFactor(0, k, T.translation(), yaw, switch_cov));
  }
  Matrix6d match_cov = Matrix6d::Zero();
  match_cov.diagonal() << 0.0025, 0.0025, 0.0025, 2.5e-5, 2.5e-5, std::pow(0.5 * M_PI / 180.0, 2);
  for (const auto& [a, b] : {std::pair{0, 15}, std::pair{1, 14}}) {
    f.push_back(SubmapMatchFactor(
        GraphKey::Origin(0, a), GraphKey::Origin(0, b),
        truth->at(static_cast<std::size_t>(a)).inverse() * truth->at(static_cast<std::size_t>(b)),
        match_cov));
  }
  for (GraphFactorRecord& r : f) r.id = id++;
  return f;
}

std::vector<Eigen::Isometry3d> Solve(const std::vector<GraphFactorRecord>& factors,
                                     double cauchy_scale = RoverGraphOptions{}.cauchy_scale) {
  RoverGraphOptions options;
  options.cauchy_scale = cauchy_scale;
  RoverGraph graph(options);
  for (const GraphFactorRecord& f : factors) AddToGraph(f, &graph);
  graph.Optimize();
  std::vector<Eigen::Isometry3d> origins;
  for (int k = 0; k < kOrigins; ++k) origins.push_back(graph.Origin(0, k));
  return origins;
}

double LargestMove(const std::vector<Eigen::Isometry3d>& a,
                   const std::vector<Eigen::Isometry3d>& b) {
  double m = 0.0;
  for (std::size_t k = 0; k < a.size(); ++k) {
    m = std::max(m, (a[k].translation() - b[k].translation()).norm());
  }
  return m;
}

TEST(GraphRobustnessTest, AMatchThatContradictsEverythingBarelyMovesTheGraph) {
  std::vector<Eigen::Isometry3d> truth;
  std::vector<GraphFactorRecord> factors = SquareLoop(&truth);
  const std::vector<Eigen::Isometry3d> clean = Solve(factors);
  // The loop closures work: the far corner is close to the truth.
  EXPECT_LT((clean[8].translation() - truth[8].translation()).norm(), 0.3);

  // Origins 4 and 11 are 20 m apart; the match claims 8 m off and 60 deg.
  GraphFactorRecord wrong =
      SubmapMatchFactor(GraphKey::Origin(0, 4), GraphKey::Origin(0, 11),
                        truth[4].inverse() * truth[11] *
                            GravityAlignedTransform({8.0, -3.0, 0.5}, 60.0 * M_PI / 180.0),
                        factors.back().covariance);
  wrong.id = 1000;
  ASSERT_TRUE(wrong.robust);
  factors.push_back(wrong);
  EXPECT_LT(LargestMove(clean, Solve(factors)), 0.1);

  // Without the robust loss (a Cauchy scale so large that it is least
  // squares) the same match tears the loop apart.
  EXPECT_GT(LargestMove(clean, Solve(factors, 1e6)), 1.0);
}

}  // namespace
}  // namespace rover::mapping
