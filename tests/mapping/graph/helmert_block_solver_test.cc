// Helmert blocking reaches the same solution as the full Ceres solve: same
// cost (1e-6 relative) and the same poses (1e-6), on a 2D and a 3D dataset,
// with contiguous blocks and with an explicit partition (chi2 objective).

#include "mapping/graph/helmert_block_solver.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

#include "mapping/graph/chordal_initialisation.h"
#include "mapping/graph/g2o_reader.h"
#include "mapping/graph/pose_graph_solver.h"

namespace rover::mapping {
namespace {

std::string DataPath(const std::string& name) {
  const char* shared = std::getenv("ROVER_SHARED_DIR");
  return std::string(shared != nullptr ? shared : "../shared") + "/data/posegraph/" + name;
}

void ExpectSameSolution(const std::string& file, HelmertBlockOptions helmert_options) {
  PoseGraph start = ReadG2oFile(DataPath(file));
  ChordalInitialisation(start);
  start.vertices_implied = false;  // Keep this start in SolvePoseGraph (kFile).
  PoseGraph full = start;
  PoseGraph blocked = start;

  PoseGraphSolverOptions options;
  options.objective = helmert_options.objective;
  options.initialisation = Initialisation::kFile;
  options.function_tolerance = 1e-15;
  options.gradient_tolerance = 1e-15;
  options.parameter_tolerance = 1e-15;
  options.max_iterations = 500;
  const PoseGraphSolverSummary reference = SolvePoseGraph(full, options);

  const HelmertBlockSummary s = HelmertBlockSolver(helmert_options).Solve(blocked);
  EXPECT_TRUE(s.converged);
  EXPECT_GT(s.blocks, 1);
  EXPECT_GT(s.separator_vertices, 0);
  EXPECT_EQ(s.separator_vertices + s.interior_vertices,
            static_cast<int>(start.vertices.size()) - 1);
  EXPECT_NEAR(s.initial_cost, reference.initial_cost, 1e-9 * reference.initial_cost);
  EXPECT_NEAR(s.final_cost, reference.final_cost, 1e-6 * reference.final_cost) << file;
  double max_dt = 0.0;
  double max_dr = 0.0;
  for (size_t v = 0; v < full.vertices.size(); ++v) {
    const Eigen::Isometry3d& a = full.vertices[v].pose;
    const Eigen::Isometry3d& b = blocked.vertices[v].pose;
    max_dt = std::max(max_dt, (a.translation() - b.translation()).norm());
    max_dr = std::max(max_dr, (a.linear() - b.linear()).norm());
  }
  EXPECT_LT(max_dt, 1e-6) << file;
  EXPECT_LT(max_dr, 1e-6) << file;
}

TEST(HelmertBlockSolverTest, MatchesFullSolveOnIntel) {
  HelmertBlockOptions o;
  o.block_size = 150;
  ExpectSameSolution("intel.g2o", o);
}

TEST(HelmertBlockSolverTest, MatchesFullSolveOnSmallGrid3D) {
  HelmertBlockOptions o;
  o.block_size = 40;
  ExpectSameSolution("smallGrid3D.g2o", o);
}

TEST(HelmertBlockSolverTest, ExplicitPartitionMatchesFullSolve) {
  // Interleaved "submaps" (vertex v in block v % 3): many separators, the
  // reduced system does most of the work; still the same solution.
  const PoseGraph g = ReadG2oFile(DataPath("CSAIL.g2o"));
  HelmertBlockOptions o;
  for (size_t v = 0; v < g.vertices.size(); ++v)
    o.block_of_vertex.push_back(static_cast<int>(v / 100 % 4));
  ExpectSameSolution("CSAIL.g2o", o);
}

}  // namespace
}  // namespace rover::mapping
