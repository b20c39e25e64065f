// Robustness to random false loop closures (seeded): with GNC, manhattan with
// 10 % and 30 % injected outliers ends within 5 % of the outlier-free F,
// evaluated on the inlier (original) edges, and rejects the outliers.
// sphere2500 (48 s at 30 %) is in bench_graph --outliers.

#include <gtest/gtest.h>

#include <cstdlib>
#include <string>
#include <vector>

#include "mapping/graph/g2o_reader.h"
#include "mapping/graph/outlier_injection.h"
#include "mapping/graph/pose_graph_solver.h"
#include "mapping/graph/se_sync_objective.h"

namespace rover::mapping {
namespace {

std::string DataPath(const std::string& name) {
  const char* shared = std::getenv("ROVER_SHARED_DIR");
  return std::string(shared != nullptr ? shared : "../shared") + "/data/posegraph/" + name;
}

class OutlierTest : public ::testing::TestWithParam<double> {};

TEST_P(OutlierTest, GncOnManhattanStaysWithinFivePercentOfOutlierFreeF) {
  const PoseGraph clean = ReadG2oFile(DataPath("manhattan.g2o"));
  PoseGraphSolverOptions options;
  options.objective = Objective::kSeSync;
  PoseGraph reference = clean;
  const double F0 = SolvePoseGraph(reference, options).F;

  PoseGraph g = clean;
  const size_t inliers = g.edges.size();
  const int injected = InjectFalseLoopClosures(g, GetParam(), 1);
  options.outliers = OutlierHandling::kGnc;
  const PoseGraphSolverSummary s = SolvePoseGraph(g, options);
  std::vector<bool> mask(g.edges.size(), false);
  int outliers_rejected = 0;
  int true_lost = 0;
  for (size_t k = 0; k < g.edges.size(); ++k) {
    mask[k] = k < inliers;
    if (!s.inlier[k]) (k < inliers ? true_lost : outliers_rejected) += 1;
  }
  const double F = SeSyncObjective(g, &mask);
  RecordProperty("outliers_rejected", outliers_rejected);
  RecordProperty("true_loops_lost", true_lost);
  EXPECT_EQ(s.rejected, outliers_rejected + true_lost);
  EXPECT_GE(outliers_rejected, injected - 2) << "of " << injected;
  EXPECT_LE(true_lost, 5);
  EXPECT_LT(std::abs(F - F0) / F0, 0.05) << "F on inlier edges " << F << " vs " << F0;
}

INSTANTIATE_TEST_SUITE_P(Manhattan, OutlierTest, ::testing::Values(0.1, 0.3),
                         [](const auto& param_info) {
                           return "Percent" +
                                  std::to_string(static_cast<int>(param_info.param * 100.0 + 0.5));
                         });

TEST(OutlierTest, ChiSquaredQuantilesMatchTables) {
  EXPECT_NEAR(ChiSquaredQuantile(1, 0.95), 3.841, 1e-3);
  EXPECT_NEAR(ChiSquaredQuantile(2, 0.99), 9.210, 1e-3);
  EXPECT_NEAR(ChiSquaredQuantile(3, 0.999), 16.266, 1e-3);
  EXPECT_NEAR(ChiSquaredQuantile(6, 0.999), 22.458, 1e-3);
  EXPECT_NEAR(InlierThreshold(2, 0.999), 2.0 * 16.266, 2e-3);
  EXPECT_NEAR(InlierThreshold(3, 0.999), 4.0 * 22.458, 4e-3);
}

}  // namespace
}  // namespace rover::mapping
