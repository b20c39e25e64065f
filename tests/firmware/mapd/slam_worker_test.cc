// mapd's graph thread with one Gauss-Newton step per update: after a loop
// closure, the steps it takes in idle time bring the published origins to
// the converged solution of the same factors, and Flush() waits for them.

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "core/geometry/so3.h"
#include "firmware/mapd/slam_worker.h"
#include "mapping/slam/graph_factor_record.h"

namespace rover::mapd {
namespace {

// A closed polygon of 30 frame switches (5 m legs, 12 deg turns) whose yaw
// drifts by 0.03 deg per switch, and a match of the last origin to the first
// that says the polygon closes: a correction of about a degree.
std::vector<mapping::GraphFactorRecord> DriftingLoop() {
  constexpr int kSwitches = 30;
  std::vector<mapping::GraphFactorRecord> factors;
  mapping::Matrix6d prior_cov = mapping::Matrix6d::Identity() * 1e-8;
  factors.push_back(mapping::OriginPriorFactor(0, 0, Eigen::Isometry3d::Identity(), prior_cov));
  const Eigen::Vector4d sigma(0.02, 0.02, 0.01, 0.003);
  const Eigen::Matrix4d switch_cov = sigma.cwiseProduct(sigma).asDiagonal();
  for (int k = 0; k < kSwitches; ++k) {
    const double yaw = 2.0 * M_PI / kSwitches + 0.03 * M_PI / 180.0;
    factors.push_back(
        mapping::FrameSwitchFactor(0, k, Eigen::Vector3d(5.0, 0.0, 0.0), yaw, switch_cov));
  }
  mapping::Matrix6d match_cov = mapping::Matrix6d::Zero();
  match_cov.diagonal() << 0.0025, 0.0025, 0.0025, 2.5e-5, 2.5e-5, std::pow(0.5 * M_PI / 180, 2);
  factors.push_back(mapping::SubmapMatchFactor(mapping::GraphKey::Origin(0, kSwitches),
                                               mapping::GraphKey::Origin(0, 0),
                                               Eigen::Isometry3d::Identity(), match_cov));
  return factors;
}

TEST(SlamWorkerTest, OneStepUpdatesAreRefinedInIdleTimeToTheConvergedSolution) {
  SlamWorker worker(mapping::RoverGraphOptions::Online(), 0);
  mapping::RoverGraph reference;  // converges at every Optimize()
  const std::vector<mapping::GraphFactorRecord> factors = DriftingLoop();
  for (std::size_t i = 0; i + 1 < factors.size(); ++i) {
    worker.Submit(factors[i]);
    mapping::AddToGraph(factors[i], &reference);
  }
  worker.Flush();
  reference.Optimize();
  worker.Submit(factors.back());
  mapping::AddToGraph(factors.back(), &reference);
  worker.Flush();
  reference.Optimize();

  const SlamStats stats = worker.Stats();
  EXPECT_EQ(stats.factors_added, factors.size());
  EXPECT_GT(stats.refinements, 0u) << "the loop closure converged in one step";
  const SlamSnapshot snap = worker.Latest();
  ASSERT_EQ(snap.origins.size(), 31u);
  double worst_m = 0.0, worst_rad = 0.0;
  for (const auto& [frame, origin] : snap.origins) {
    const Eigen::Isometry3d expected = reference.Origin(0, frame);
    worst_m =
        std::max(worst_m, (origin.T_world_origin.translation() - expected.translation()).norm());
    worst_rad = std::max(
        worst_rad, LogSO3(origin.T_world_origin.linear().transpose() * expected.linear()).norm());
  }
  std::printf("%llu idle-time steps; largest gap to the converged graph %.3f mm %.4f deg\n",
              static_cast<unsigned long long>(stats.refinements), 1e3 * worst_m,
              worst_rad * 180.0 / M_PI);
  EXPECT_LT(worst_m, 5e-3);
  EXPECT_LT(worst_rad, 0.02 * M_PI / 180.0);
  // The last idle-time step published the origins it moved.
  EXPECT_EQ(snap.origins_update, snap.update);
}

}  // namespace
}  // namespace rover::mapd
