#include "mapping/graph/chordal_initialisation.h"

#include <Eigen/SVD>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <cstdlib>
#include <deque>

#include "mapping/graph/graph_connectivity.h"
#include "mapping/graph/se_sync_objective.h"

namespace rover::mapping {
namespace {

Eigen::Matrix3d ProjectToSO3(const Eigen::Matrix3d& M) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(M, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
  D(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0.0 ? -1.0 : 1.0;
  return svd.matrixU() * D * svd.matrixV().transpose();
}

void AddBlock(std::vector<Eigen::Triplet<double>>& t, int row, int col,
              const Eigen::Matrix3d& block) {
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      if (block(r, c) != 0.0) t.emplace_back(row + r, col + c, block(r, c));
    }
  }
}

}  // namespace

void ChordalInitialisation(PoseGraph& graph, const std::vector<double>* edge_weights) {
  CheckGaugeAndFinite(graph);
  const int n = static_cast<int>(graph.vertices.size());
  if (n <= 1) return;
  const auto index = VertexIndex(graph);
  // Unknown k (vertex k >= 1) is at offset k - 1; the anchor is eliminated.
  const int m = n - 1;
  const Eigen::Matrix3d I3 = Eigen::Matrix3d::Identity();
  const Eigen::Matrix3d X0 = graph.vertices[0].pose.linear().transpose();

  // Rotations: X_k = R_k^T (3 x 3), residual X_j - R~^T X_i, weight kappa.
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(graph.edges.size() * 36);
  Eigen::MatrixXd b = Eigen::MatrixXd::Zero(3 * m, 3);
  std::vector<IsotropicWeights> weights(graph.edges.size());
  for (size_t k = 0; k < graph.edges.size(); ++k) {
    const PoseEdge& e = graph.edges[k];
    IsotropicWeights w = SeSyncWeights(e, graph.dimension);
    if (edge_weights != nullptr) {
      w.kappa *= (*edge_weights)[k];
      w.tau *= (*edge_weights)[k];
    }
    weights[k] = w;
    if (w.kappa <= 0.0) continue;
    const int i = index.at(e.from) - 1;
    const int j = index.at(e.to) - 1;
    const Eigen::Matrix3d A = e.measurement.linear().transpose();  // x_j = A x_i
    if (i >= 0) AddBlock(triplets, 3 * i, 3 * i, w.kappa * I3);
    if (j >= 0) AddBlock(triplets, 3 * j, 3 * j, w.kappa * I3);
    if (i >= 0 && j >= 0) {
      AddBlock(triplets, 3 * i, 3 * j, -w.kappa * A.transpose());
      AddBlock(triplets, 3 * j, 3 * i, -w.kappa * A);
    } else if (i < 0) {  // x_i = X0 known: residual x_j - A X0.
      b.middleRows<3>(3 * j) += w.kappa * A * X0;
    } else {  // x_j = X0 known: residual X0 - A x_i.
      b.middleRows<3>(3 * i) += w.kappa * A.transpose() * X0;
    }
  }
  Eigen::SparseMatrix<double> H(3 * m, 3 * m);
  H.setFromTriplets(triplets.begin(), triplets.end());
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(H);
  if (ldlt.info() != Eigen::Success) {
    throw GraphError(graph.source + ": chordal initialisation: rotation system is singular");
  }
  const Eigen::MatrixXd X = ldlt.solve(b);
  std::vector<Eigen::Matrix3d> R(static_cast<size_t>(n));
  R[0] = graph.vertices[0].pose.linear();
  for (int k = 1; k < n; ++k) {
    R[static_cast<size_t>(k)] = ProjectToSO3(X.middleRows<3>(3 * (k - 1)).transpose());
  }

  // Translations: residual t_j - t_i - R_i t~, weight tau (scalar Laplacian).
  triplets.clear();
  Eigen::MatrixXd bt = Eigen::MatrixXd::Zero(m, 3);
  const Eigen::Vector3d t0 = graph.vertices[0].pose.translation();
  for (size_t k = 0; k < graph.edges.size(); ++k) {
    const PoseEdge& e = graph.edges[k];
    const double tau = weights[k].tau;
    if (tau <= 0.0) continue;
    const int vi = index.at(e.from);
    const int vj = index.at(e.to);
    const int i = vi - 1;
    const int j = vj - 1;
    const Eigen::RowVector3d d =
        (tau * R[static_cast<size_t>(vi)] * e.measurement.translation()).transpose();
    if (i >= 0) triplets.emplace_back(i, i, tau);
    if (j >= 0) triplets.emplace_back(j, j, tau);
    if (i >= 0 && j >= 0) {
      triplets.emplace_back(i, j, -tau);
      triplets.emplace_back(j, i, -tau);
      bt.row(j) += d;
      bt.row(i) -= d;
    } else if (i < 0) {
      bt.row(j) += d + tau * t0.transpose();
    } else {
      bt.row(i) += -d + tau * t0.transpose();
    }
  }
  Eigen::SparseMatrix<double> L(m, m);
  L.setFromTriplets(triplets.begin(), triplets.end());
  ldlt.compute(L);
  if (ldlt.info() != Eigen::Success) {
    throw GraphError(graph.source + ": chordal initialisation: translation system is singular");
  }
  const Eigen::MatrixXd T = ldlt.solve(bt);
  for (int k = 1; k < n; ++k) {
    Eigen::Isometry3d& pose = graph.vertices[static_cast<size_t>(k)].pose;
    pose.linear() = R[static_cast<size_t>(k)];
    pose.translation() = T.row(k - 1).transpose();
  }
}

void OdometryInitialisation(PoseGraph& graph) {
  CheckGaugeAndFinite(graph);
  const auto index = VertexIndex(graph);
  const size_t n = graph.vertices.size();
  std::vector<std::vector<size_t>> adjacency(n);
  for (size_t k = 0; k < graph.edges.size(); ++k) {
    const PoseEdge& e = graph.edges[k];
    adjacency[static_cast<size_t>(index.at(e.from))].push_back(k);
    adjacency[static_cast<size_t>(index.at(e.to))].push_back(k);
  }
  // Odometry edges first so the tree follows the trajectory.
  for (auto& list : adjacency) {
    std::stable_partition(list.begin(), list.end(), [&](size_t k) {
      return std::llabs(graph.edges[k].to - graph.edges[k].from) == 1;
    });
  }
  std::vector<bool> done(n, false);
  std::deque<size_t> queue{0};
  done[0] = true;
  while (!queue.empty()) {
    const size_t v = queue.front();
    queue.pop_front();
    for (const size_t k : adjacency[v]) {
      const PoseEdge& e = graph.edges[k];
      const auto i = static_cast<size_t>(index.at(e.from));
      const auto j = static_cast<size_t>(index.at(e.to));
      const size_t other = (i == v) ? j : i;
      if (done[other]) continue;
      done[other] = true;
      if (other == j) {
        graph.vertices[j].pose = graph.vertices[i].pose * e.measurement;
      } else {
        graph.vertices[i].pose = graph.vertices[j].pose * e.measurement.inverse();
      }
      queue.push_back(other);
    }
  }
}

}  // namespace rover::mapping
