// g2o reading/writing: full-precision round trip and file:line errors.

#include <gtest/gtest.h>

#include <sstream>
#include <string>

#include "mapping/graph/g2o_reader.h"
#include "mapping/graph/g2o_writer.h"
#include "mapping/graph/pose_graph_solver.h"

namespace rover::mapping {
namespace {

constexpr const char* kInfo3 = " 1 0 0 0 0 0 1 0 0 0 0 1 0 0 0 1 0 0 1 0 1";

std::string ErrorOf(const std::string& text) {
  std::istringstream in(text);
  try {
    (void)ReadG2o(in, "bad.g2o");
  } catch (const GraphError& e) {
    return e.what();
  }
  return "no error";
}

TEST(G2oIoTest, RoundTrip3dKeepsEveryDigit) {
  const std::string text = std::string("VERTEX_SE3:QUAT 0 0 0 0 0 0 0 1\n") +
                           "VERTEX_SE3:QUAT 1 0.1234567890123456 -2.000000000000001 "
                           "3.3333333333333335 0.1 0.2 0.3 0.9273618495495703\n" +
                           "EDGE_SE3:QUAT 0 1 1.0000000000000002 2 3 0 0 0.0499791692706783 "
                           "0.9987502603949663" +
                           kInfo3 + "\n";
  std::istringstream in(text);
  const PoseGraph a = ReadG2o(in, "a.g2o");
  std::stringstream buffer;
  WriteG2o(a, buffer);
  const PoseGraph b = ReadG2o(buffer, "b.g2o");
  ASSERT_EQ(b.vertices.size(), 2u);
  ASSERT_EQ(b.edges.size(), 1u);
  EXPECT_EQ(b.vertices[1].pose.translation(), a.vertices[1].pose.translation());
  EXPECT_LT((b.vertices[1].pose.linear() - a.vertices[1].pose.linear()).cwiseAbs().maxCoeff(),
            1e-15);
  EXPECT_EQ(b.edges[0].measurement.translation().x(), 1.0000000000000002);
  EXPECT_EQ(b.edges[0].information, a.edges[0].information);
  // Quaternions go through a rotation matrix: equal to the last bit or two.
  EXPECT_LT(
      (b.edges[0].measurement.linear() - a.edges[0].measurement.linear()).cwiseAbs().maxCoeff(),
      1e-15);
}

TEST(G2oIoTest, RoundTrip2d) {
  std::istringstream in(
      "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 1.0000000000000002 0.3 -3.1\n"
      "EDGE_SE2 0 1 1 0.1 0.2 10 0.5 0 20 0 30.000000000000004\n");
  const PoseGraph a = ReadG2o(in, "a.g2o");
  EXPECT_EQ(a.dimension, 2);
  std::stringstream buffer;
  WriteG2o(a, buffer);
  EXPECT_NE(buffer.str().find("VERTEX_SE2 1 1.0000000000000002 0.3 -3.1"), std::string::npos)
      << buffer.str();
  EXPECT_NE(buffer.str().find("30.000000000000004"), std::string::npos);
}

TEST(G2oIoTest, VertexlessFileImpliesVertices) {
  std::istringstream in("EDGE_SE2 0 1 1 0 0 1 0 0 1 0 1\nEDGE_SE2 1 2 1 0 0 1 0 0 1 0 1\n");
  const PoseGraph g = ReadG2o(in, "e.g2o");
  EXPECT_TRUE(g.vertices_implied);
  EXPECT_EQ(g.vertices.size(), 3u);
}

TEST(G2oIoTest, MalformedLineNamesFileAndLine) {
  EXPECT_EQ(ErrorOf("VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 0 zero 0\n"),
            "bad.g2o:2: expected a number for y, found 'zero'");
  EXPECT_EQ(ErrorOf("VERTEX_SE2 0 0 0 0\n\nVERTEX_SE2 1 0 0\n"),
            "bad.g2o:3: expected 4 values after VERTEX_SE2, found 3");
  EXPECT_EQ(ErrorOf("VERTEX_SE2 0 0 0 0\nVERTEX_XYZ 1 0 0 0\n"),
            "bad.g2o:2: expected VERTEX_SE3:QUAT, EDGE_SE3:QUAT, VERTEX_SE2, EDGE_SE2 or FIX, "
            "found 'VERTEX_XYZ'");
}

TEST(G2oIoTest, MissingVertexNamesFileAndLine) {
  EXPECT_EQ(ErrorOf("VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 0 0 0\nEDGE_SE2 1 7 1 0 0 1 0 0 1 0 1\n"),
            "bad.g2o:3: edge 1 -> 7 references vertex 7, which no VERTEX line defines");
}

TEST(G2oIoTest, NonPositiveDefiniteBlockNamesFileAndLine) {
  // Translation block [[1, 2], [2, 1]]: no objective can use it.
  std::string message =
      ErrorOf("VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 0 0 0\nEDGE_SE2 0 1 1 0 0 1 2 0 1 0 1\n");
  EXPECT_EQ(message,
            "bad.g2o:3: expected a positive-definite translation block (x, y) of the information "
            "matrix, found one with smallest eigenvalue -1");
  message = ErrorOf(
      "VERTEX_SE3:QUAT 0 0 0 0 0 0 0 1\nVERTEX_SE3:QUAT 1 0 0 0 0 0 0 1\n"
      "EDGE_SE3:QUAT 0 1 1 0 0 0 0 0 1 1 0 0 0 0 0 1 0 0 0 0 1 0 0 0 0 0 0 1 0 1\n");
  EXPECT_EQ(message.rfind("bad.g2o:3: expected a positive-definite rotation block (qx, qy, qz)", 0),
            0u)
      << message;
}

// Diagonal blocks I3, off-diagonal block 2 I3: eigenvalues 3 and -1.
constexpr const char* kIndefinite3d =
    "VERTEX_SE3:QUAT 0 0 0 0 0 0 0 1\nVERTEX_SE3:QUAT 1 1 0 0 0 0 0 1\n"
    "EDGE_SE3:QUAT 0 1 1 0 0 0 0 0 1 1 0 0 2 0 0 1 0 0 2 0 1 0 0 2 1 0 0 1 0 1\n";

TEST(G2oIoTest, IndefiniteAsAWholeIsReadAndRefusedByChi2) {
  std::istringstream in(kIndefinite3d);
  PoseGraph g = ReadG2o(in, "g.g2o");
  ASSERT_EQ(g.edges.size(), 1u);
  PoseGraph chi2 = g;
  try {
    SolvePoseGraph(chi2, PoseGraphSolverOptions{});
    FAIL() << "no error";
  } catch (const GraphError& e) {
    EXPECT_EQ(std::string(e.what()).rfind(
                  "g.g2o:3: edge 0 -> 1: expected a positive-definite information matrix for the "
                  "chi2 objective, found smallest eigenvalue -1",
                  0),
              0u)
        << e.what();
  }
}

TEST(G2oIoTest, SeSyncObjectiveUsesTheBlocksAndSaysWhatItIgnored) {
  std::istringstream in(kIndefinite3d);
  PoseGraph g = ReadG2o(in, "g.g2o");
  PoseGraphSolverOptions o;
  o.objective = Objective::kSeSync;
  const PoseGraphSolverSummary s = SolvePoseGraph(g, o);
  EXPECT_EQ(s.information.off_diagonal_ignored, 1);
  EXPECT_EQ(s.information.indefinite, 1);
  EXPECT_EQ(s.information.Describe(),
            "1 edge: off-diagonal blocks ignored; 1 of them: info matrix indefinite as a whole "
            "(first on line 3)");
  EXPECT_LT(s.F, 1e-12);  // One exact edge: F* = 0.
  // A positive-definite matrix with an off-diagonal block is still noted.
  std::istringstream pd(
      "VERTEX_SE3:QUAT 0 0 0 0 0 0 0 1\nVERTEX_SE3:QUAT 1 1 0 0 0 0 0 1\n"
      "EDGE_SE3:QUAT 0 1 1 0 0 0 0 0 1 1 0 0 0.5 0 0 1 0 0 0 0 1 0 0 0 1 0 0 1 0 1\n");
  PoseGraph h = ReadG2o(pd, "h.g2o");
  EXPECT_EQ(CheckInformation(h, Objective::kSeSync).Describe(),
            "1 edge: off-diagonal blocks ignored");
  EXPECT_EQ(CheckInformation(h, Objective::kChi2).Describe(), "");
}

TEST(G2oIoTest, NanInputNamesFileAndLine) {
  const std::string message = ErrorOf("VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 nan 0 0\n");
  EXPECT_EQ(message, "bad.g2o:2: expected a finite number for x, found 'nan' (NaN input)");
}

TEST(G2oIoTest, UnanchoredComponentIsAGaugeProblem) {
  std::istringstream in(
      "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 1 0 0\nVERTEX_SE2 2 2 0 0\nVERTEX_SE2 3 3 0 0\n"
      "EDGE_SE2 0 1 1 0 0 1 0 0 1 0 1\nEDGE_SE2 2 3 1 0 0 1 0 0 1 0 1\n");
  PoseGraph g = ReadG2o(in, "split.g2o");
  try {
    SolvePoseGraph(g, PoseGraphSolverOptions{});
    FAIL() << "no error";
  } catch (const GraphError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("gauge problem"), std::string::npos) << m;
    EXPECT_NE(m.find("component 1: ids 2, 3 (2 vertices)"), std::string::npos) << m;
  }
}

TEST(G2oIoTest, NanVertexPoseIsRejectedBySolver) {
  std::istringstream in("VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 1 0 0\nEDGE_SE2 0 1 1 0 0 1 0 0 1 0 1\n");
  PoseGraph g = ReadG2o(in, "nan.g2o");
  g.vertices[1].pose.translation().x() = std::numeric_limits<double>::quiet_NaN();
  try {
    SolvePoseGraph(g, PoseGraphSolverOptions{});
    FAIL() << "no error";
  } catch (const GraphError& e) {
    EXPECT_NE(std::string(e.what()).find("NaN input: vertex 1"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace rover::mapping
