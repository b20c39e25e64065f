#ifndef ROVER_MAPPING_GRAPH_CHORDAL_INITIALISATION_H_
#define ROVER_MAPPING_GRAPH_CHORDAL_INITIALISATION_H_

// Initial guesses for a pose graph, written into graph.vertices. The first
// vertex keeps its pose (it is the anchor of the gauge).
//
// Chordal initialisation (Carlone et al., "Initialization techniques for 3D
// SLAM"; Martinec & Pajdla): relax SO(3) to all 3x3 matrices and minimise
// sum kappa_ij |R_j - R_i R~_ij|_F^2, a sparse linear least-squares problem
// (the rows of the rotations decouple: three right-hand sides, one
// factorisation), project each R_i onto SO(3) with an SVD, then minimise
// sum tau_ij |t_j - t_i - R_i t~_ij|^2 over the translations (a weighted graph
// Laplacian, again three right-hand sides). Both use Eigen's SimplicialLDLT.
// 2D graphs go through the same code in their SE(3) embedding (the solution
// stays planar).

#include <vector>

#include "mapping/graph/pose_graph.h"

namespace rover::mapping {

/// Replaces every vertex pose but the first by the chordal estimate. Weights
/// are SE-Sync's kappa and tau (se_sync_objective.h), each multiplied by
/// edge_weights[k] if given (one entry per edge, >= 0; 0 drops the edge).
/// Throws GraphError if the graph is not connected (see CheckGaugeAndFinite).
void ChordalInitialisation(PoseGraph& graph, const std::vector<double>* edge_weights = nullptr);

/// Replaces every vertex pose but the first by composing edge measurements
/// along a breadth-first spanning tree from the first vertex, preferring
/// odometry edges (|to - from| == 1): "starting from odometry".
void OdometryInitialisation(PoseGraph& graph);

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_GRAPH_CHORDAL_INITIALISATION_H_
