// Quality bar on the small standard datasets: with the SE-Sync objective the
// final F matches the published certified optimum (relative difference
// < 5e-4, the table's printed precision); every solve converges.

#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

#include "mapping/graph/g2o_reader.h"
#include "mapping/graph/pose_graph_solver.h"
#include "mapping/graph/se_sync_objective.h"

namespace rover::mapping {
namespace {

std::string DataPath(const std::string& name) {
  const char* shared = std::getenv("ROVER_SHARED_DIR");
  return std::string(shared != nullptr ? shared : "../shared") + "/data/posegraph/" + name;
}

struct Case {
  const char* file;
  double published_F;  // 0: none published.
};

class DatasetQualityTest : public ::testing::TestWithParam<Case> {};

TEST_P(DatasetQualityTest, SeSyncObjectiveReachesPublishedOptimum) {
  PoseGraph graph = ReadG2oFile(DataPath(GetParam().file));
  PoseGraphSolverOptions options;
  options.objective = Objective::kSeSync;
  const PoseGraphSolverSummary s = SolvePoseGraph(graph, options);
  EXPECT_TRUE(s.converged) << s.message;
  EXPECT_NEAR(s.F, SeSyncObjective(graph), 1e-9 * s.F);
  EXPECT_NEAR(2.0 * s.final_cost, s.F, 1e-9 * s.F);  // Ceres cost is F / 2.
  if (GetParam().published_F > 0.0) {
    EXPECT_LT(std::abs(s.F - GetParam().published_F) / GetParam().published_F, 5e-4)
        << GetParam().file << ": F = " << s.F;
  }
}

TEST_P(DatasetQualityTest, Chi2ObjectiveDecreasesAndConverges) {
  PoseGraph graph = ReadG2oFile(DataPath(GetParam().file));
  PoseGraphSolverOptions options;
  const PoseGraphSolverSummary s = SolvePoseGraph(graph, options);
  EXPECT_TRUE(s.converged) << s.message;
  EXPECT_LE(s.final_cost, s.initial_cost);
  EXPECT_NEAR(2.0 * s.final_cost, s.chi2, 1e-9 * s.chi2);
}

INSTANTIATE_TEST_SUITE_P(Small, DatasetQualityTest,
                         ::testing::Values(Case{"tinyGrid3D.g2o", 0.0},
                                           Case{"smallGrid3D.g2o", 0.0}, Case{"CSAIL.g2o", 3.170e1},
                                           Case{"intel.g2o", 5.235e1}),
                         [](const auto& param_info) {
                           std::string name = param_info.param.file;
                           return name.substr(0, name.find('.'));
                         });

// The chordal initialisation matters: F from odometry is no better.
TEST(DatasetQualityTest, ChordalStartIsNoWorseThanOdometryOnIntel) {
  PoseGraph a = ReadG2oFile(DataPath("intel.g2o"));
  PoseGraph b = a;
  PoseGraphSolverOptions options;
  options.objective = Objective::kSeSync;
  const double chordal = SolvePoseGraph(a, options).F;
  options.initialisation = Initialisation::kOdometry;
  const double odometry = SolvePoseGraph(b, options).F;
  EXPECT_LE(chordal, odometry * (1.0 + 1e-6));
}

}  // namespace
}  // namespace rover::mapping
