// rover-graph subcommands called as functions: solve writes a full-precision
// result and a RESULT line; bad input exits 1 naming file and line.

#include <gtest/gtest.h>

#include <unistd.h>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "host/graph/commands.h"
#include "mapping/graph/g2o_reader.h"
#include "mapping/graph/se_sync_objective.h"

namespace rover::host {
namespace {

std::string DataPath(const std::string& name) {
  const char* shared = std::getenv("ROVER_SHARED_DIR");
  return std::string(shared != nullptr ? shared : "../shared") + "/data/posegraph/" + name;
}

std::filesystem::path TempPath(const std::string& name) {
  return std::filesystem::temp_directory_path() /
         ("rover_graph_tool_test_" + std::to_string(::getpid()) + "_" + name);
}

TEST(RoverGraphToolTest, SolveWritesResultAndSummary) {
  SolveCommandOptions options;
  options.input = DataPath("intel.g2o");
  options.output = TempPath("intel_out.g2o").string();
  options.solver.objective = mapping::Objective::kSeSync;
  std::ostringstream out, err;
  ASSERT_EQ(RunSolve(options, out, err), 0) << err.str();
  EXPECT_NE(out.str().find("RESULT dataset=intel objective=sesync iterations="), std::string::npos)
      << out.str();
  EXPECT_NE(out.str().find("  iter 1  cost "), std::string::npos);  // Progress lines.
  // intel's information matrices have x-theta entries: SE-Sync ignores them.
  EXPECT_NE(out.str().find("  ignored: 2512 edges: off-diagonal blocks ignored\n"),
            std::string::npos)
      << out.str();
  EXPECT_NE(out.str().find("  certificate: certified (lambda_min "), std::string::npos);
  EXPECT_NE(out.str().find(" certified=yes lambda_min="), std::string::npos);
  const mapping::PoseGraph solved = mapping::ReadG2oFile(options.output);
  EXPECT_NEAR(mapping::SeSyncObjective(solved), 52.35, 0.03);
  std::filesystem::remove(options.output);
}

TEST(RoverGraphToolTest, MalformedInputExitsOneWithFileAndLine) {
  const auto path = TempPath("bad.g2o");
  {
    std::ofstream f(path);
    f << "VERTEX_SE2 0 0 0 0\nEDGE_SE2 0 1 1 0 0 1 0 0 1 0\n";
  }
  SolveCommandOptions options;
  options.input = path.string();
  options.output = TempPath("never.g2o").string();
  std::ostringstream out, err;
  EXPECT_EQ(RunSolve(options, out, err), 1);
  EXPECT_NE(err.str().find(path.string() + ":2: expected 11 values after EDGE_SE2, found 10"),
            std::string::npos)
      << err.str();
  std::filesystem::remove(path);
}

TEST(RoverGraphToolTest, Chi2RefusesAnIndefiniteMatrixNamingEdgeAndLine) {
  const auto path = TempPath("indefinite.g2o");
  {
    std::ofstream f(path);
    f << "VERTEX_SE3:QUAT 0 0 0 0 0 0 0 1\nVERTEX_SE3:QUAT 1 1 0 0 0 0 0 1\n"
         "EDGE_SE3:QUAT 0 1 1 0 0 0 0 0 1 1 0 0 2 0 0 1 0 0 2 0 1 0 0 2 1 0 0 1 0 1\n";
  }
  SolveCommandOptions options;
  options.input = path.string();
  options.output = TempPath("indefinite_out.g2o").string();
  std::ostringstream out, err;
  EXPECT_EQ(RunSolve(options, out, err), 1);
  EXPECT_NE(err.str().find(path.string() +
                           ":3: edge 0 -> 1: expected a positive-definite information matrix "
                           "for the chi2 objective"),
            std::string::npos)
      << err.str();
  options.solver.objective = mapping::Objective::kSeSync;
  std::ostringstream out2, err2;
  EXPECT_EQ(RunSolve(options, out2, err2), 0) << err2.str();
  EXPECT_NE(out2.str().find("ignored: 1 edge: off-diagonal blocks ignored; 1 of them: info "
                            "matrix indefinite as a whole (first on line 3)"),
            std::string::npos)
      << out2.str();
  std::filesystem::remove(path);
  std::filesystem::remove(options.output);
}

TEST(RoverGraphToolTest, InfoReportsCountsAndComponents) {
  std::ostringstream out, err;
  ASSERT_EQ(RunInfo(DataPath("CSAIL.g2o"), out, err), 0) << err.str();
  EXPECT_NE(out.str().find("vertices:        1045"), std::string::npos) << out.str();
  EXPECT_NE(out.str().find("edges:           1172 (128 loop closures"), std::string::npos);
  EXPECT_NE(out.str().find("components:      1 (connected)"), std::string::npos);
}

}  // namespace
}  // namespace rover::host
