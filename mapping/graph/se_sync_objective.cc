#include "mapping/graph/se_sync_objective.h"

#include <Eigen/Cholesky>

#include "mapping/graph/relative_pose_2d_cost.h"
#include "mapping/graph/relative_pose_3d_cost.h"

namespace rover::mapping {

IsotropicWeights SeSyncWeights(const PoseEdge& edge, int dimension) {
  IsotropicWeights w;
  if (dimension == 2) {
    const Eigen::Matrix3d I = PlanarInformation(edge.information);
    w.tau = 2.0 / I.topLeftCorner<2, 2>().inverse().trace();
    w.kappa = I(2, 2);
  } else {
    w.tau = 3.0 / edge.information.topLeftCorner<3, 3>().inverse().trace();
    w.kappa = 3.0 / (2.0 * edge.information.bottomRightCorner<3, 3>().inverse().trace());
  }
  return w;
}

double SeSyncEdgeTerm(const PoseEdge& edge, int dimension, const Eigen::Isometry3d& T_w_i,
                      const Eigen::Isometry3d& T_w_j) {
  const IsotropicWeights w = SeSyncWeights(edge, dimension);
  const Eigen::Matrix3d dR = T_w_j.linear() - T_w_i.linear() * edge.measurement.linear();
  const Eigen::Vector3d dt =
      T_w_j.translation() - T_w_i.translation() - T_w_i.linear() * edge.measurement.translation();
  return w.kappa * dR.squaredNorm() + w.tau * dt.squaredNorm();
}

double Chi2EdgeTerm(const PoseEdge& edge, int dimension, const Eigen::Isometry3d& T_w_i,
                    const Eigen::Isometry3d& T_w_j) {
  if (dimension == 2) {
    const Eigen::Vector3d pi = PlanarPose(T_w_i);
    const Eigen::Vector3d pj = PlanarPose(T_w_j);
    const RelativePose2dCost cost(PlanarPose(edge.measurement),
                                  PlanarInformation(edge.information));
    const double* params[2] = {pi.data(), pj.data()};
    Eigen::Vector3d r;
    cost.Evaluate(params, r.data(), nullptr);
    return r.squaredNorm();
  }
  const RelativePose3dCost cost(edge.measurement, edge.information);
  const Eigen::Matrix<double, 6, 1> e = cost.Error(T_w_i, T_w_j);
  return e.dot(edge.information * e);
}

std::unordered_map<int64_t, int> VertexIndex(const PoseGraph& graph) {
  std::unordered_map<int64_t, int> index;
  index.reserve(graph.vertices.size());
  for (size_t k = 0; k < graph.vertices.size(); ++k) {
    index.emplace(graph.vertices[k].id, static_cast<int>(k));
  }
  return index;
}

namespace {

template <typename Term>
double Sum(const PoseGraph& graph, const std::vector<bool>* mask, Term term) {
  const auto index = VertexIndex(graph);
  double total = 0.0;
  for (size_t k = 0; k < graph.edges.size(); ++k) {
    if (mask != nullptr && !(*mask)[k]) continue;
    const PoseEdge& e = graph.edges[k];
    const auto& vi = graph.vertices[static_cast<size_t>(index.at(e.from))];
    const auto& vj = graph.vertices[static_cast<size_t>(index.at(e.to))];
    total += term(e, graph.dimension, vi.pose, vj.pose);
  }
  return total;
}

}  // namespace

double SeSyncObjective(const PoseGraph& graph, const std::vector<bool>* edge_mask) {
  return Sum(graph, edge_mask, SeSyncEdgeTerm);
}

double Chi2Objective(const PoseGraph& graph, const std::vector<bool>* edge_mask) {
  return Sum(graph, edge_mask, Chi2EdgeTerm);
}

}  // namespace rover::mapping
