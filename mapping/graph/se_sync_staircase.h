#ifndef ROVER_MAPPING_GRAPH_SE_SYNC_STAIRCASE_H_
#define ROVER_MAPPING_GRAPH_SE_SYNC_STAIRCASE_H_

// SE-Sync's Riemannian staircase, for a solution whose certificate failed
// (se_sync_certificate.h): the rotations Y are a critical point but S has a
// negative eigenvalue lambda_min with eigenvector v. One rank up, Y is a
// saddle of f(Y) = tr(Y Q Y^T) over St(d, r)^n (r = d + 1) and [0; v^T] is a
// direction of negative curvature: step along it (saddle escape), descend
// at rank r (Riemannian gradient descent with Barzilai-Borwein steps and an
// Armijo line search, polar retraction per block), certify at rank r, and
// climb further while that fails. The result is rounded to SO(d)^n as SE-Sync
// does (rank-d truncated SVD of Y, the reflection that makes most
// determinants positive, each block projected onto SO(d)), translations
// optimal for it.

#include <string>

#include "mapping/graph/pose_graph.h"
#include "mapping/graph/se_sync_certificate.h"

namespace rover::mapping {

struct SeSyncStaircaseOptions {
  /// Highest relaxation rank; 0: d + 3.
  int max_rank = 0;
  /// Gradient steps per rank at most.
  int max_iterations = 5000;
  /// Stop the descent at a rank when |grad f| falls below this fraction of
  /// its value right after the escape.
  double relative_gradient_tolerance = 1e-7;
  SeSyncCertificateOptions certificate;

  /// Throws std::invalid_argument naming the key that is out of range.
  void Validate() const;
};

struct SeSyncStaircaseSummary {
  int rank = 0;                   ///< Rank reached (of the last level descended).
  int iterations = 0;             ///< Gradient steps over all levels.
  bool certified = false;         ///< The rank-`rank` solution was certified.
  double relaxation_value = 0.0;  ///< f(Y) at the last level.
  std::string message;
};

/// Climbs from the rotations of `graph` (rank d), whose certificate is
/// `start` (not certified), and writes the rounded rotations and their
/// optimal translations into graph.vertices (vertex 0 keeps its translation).
SeSyncStaircaseSummary ClimbSeSyncStaircase(PoseGraph& graph, const SeSyncCertificate& start,
                                            const SeSyncStaircaseOptions& options = {});

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_GRAPH_SE_SYNC_STAIRCASE_H_
