#ifndef ROVER_MAPPING_GRAPH_SE_SYNC_OBJECTIVE_H_
#define ROVER_MAPPING_GRAPH_SE_SYNC_OBJECTIVE_H_

// The two objectives of a g2o pose graph, evaluated at its vertex poses:
//  * SE-Sync's isotropic objective
//      F = sum_ij kappa_ij |R_j - R_i R~_ij|_F^2 + tau_ij |t_j - t_i - R_i t~_ij|^2,
//    with 3D weights tau = 3 / tr(I_tt^-1), kappa = 3 / (2 tr(I_rr^-1)) and 2D
//    weights tau = 2 / tr(I_tt^-1), kappa = I_33 (I the edge information);
//  * g2o's chi2 = sum_ij e_ij^T Omega_ij e_ij (see RelativePose3dCost and
//    RelativePose2dCost for e).

#include <cstdint>
#include <unordered_map>
#include <vector>

#include "mapping/graph/pose_graph.h"

namespace rover::mapping {

struct IsotropicWeights {
  double kappa = 0.0;  ///< Rotation weight.
  double tau = 0.0;    ///< Translation weight.
};

/// SE-Sync's weights of one edge of a graph of the given dimension (2 or 3).
IsotropicWeights SeSyncWeights(const PoseEdge& edge, int dimension);

/// Contribution of one edge to F for the poses T_w_i, T_w_j.
double SeSyncEdgeTerm(const PoseEdge& edge, int dimension, const Eigen::Isometry3d& T_w_i,
                      const Eigen::Isometry3d& T_w_j);

/// Contribution of one edge to chi2.
double Chi2EdgeTerm(const PoseEdge& edge, int dimension, const Eigen::Isometry3d& T_w_i,
                    const Eigen::Isometry3d& T_w_j);

/// Map from vertex id to its index in graph.vertices.
std::unordered_map<int64_t, int> VertexIndex(const PoseGraph& graph);

/// F over all edges, or only those with edge_mask[k] true if a mask of
/// graph.edges.size() entries is given.
double SeSyncObjective(const PoseGraph& graph, const std::vector<bool>* edge_mask = nullptr);

/// chi2 over all edges (or the masked ones).
double Chi2Objective(const PoseGraph& graph, const std::vector<bool>* edge_mask = nullptr);

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_GRAPH_SE_SYNC_OBJECTIVE_H_
