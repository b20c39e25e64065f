#ifndef ROVER_MAPPING_GRAPH_SE_SYNC_CERTIFICATE_H_
#define ROVER_MAPPING_GRAPH_SE_SYNC_CERTIFICATE_H_

// SE-Sync's optimality certificate (Rosen, Carlone, Bandeira, Leonard, IJRR
// 2019) for the isotropic objective F of se_sync_objective.h.
//
// With the rotations stacked as Y = [Y_1 ... Y_n] (r x dn, Y_i = R_i for
// r = d) and the translations p (r x n), F = tr([p Y] M [p Y]^T) with the
// sparse data matrix
//     M = [ L_tau   V              ]
//         [ V^T     L_rho + Sigma  ]
// (L_tau: tau-weighted graph Laplacian; L_rho: kappa-weighted connection
// Laplacian, blocks kappa I on the diagonal and -kappa R~_ij at (i, j);
// Sigma: block diagonal, sum of tau t~ t~^T over the edges leaving i; V:
// rows j / i of edge ij get -tau t~^T / +tau t~^T in block i). Eliminating
// the translations leaves the rotation-only problem F(Y) = tr(Y Q Y^T),
//     Q = L_rho + Sigma - V^T L_tau^+ V        (dense: used as an operator).
// At a critical point Y the Lagrange multipliers are the symmetric blocks
// Lambda_i = sym((Q Y^T)_i Y_i) and the certificate matrix is S = Q - Lambda.
// If S is positive semidefinite, Y^T Y solves SE-Sync's semidefinite
// relaxation, so (for r = d) the rotations are a global optimum; otherwise the
// eigenvector of a negative eigenvalue is a descent direction one rank up
// (the Riemannian staircase's saddle escape).
//
// S is dense, but S + sigma I is positive definite exactly when the sparse
//     K(sigma) = [ L_r    V_r                          ]
//                [ V_r^T  L_rho + Sigma - Lambda + sigma I ]
// is (L_r, V_r: vertex 0's translation row and column removed; S + sigma I
// is the Schur complement of L_r in K(sigma)). So one sparse Cholesky
// factorisation of K(eta) (CHOLMOD) decides lambda_min(S) > -eta, and solves
// with K(sigma) apply (S + sigma I)^-1: the minimum eigenvalue itself comes
// from shifted inverse subspace iteration with Rayleigh-Ritz on S.

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <cstdint>
#include <memory>

#include "mapping/graph/pose_graph.h"

namespace rover::mapping {

struct SeSyncCertificateOptions {
  /// S counts as positive semidefinite (the solution is certified) if
  /// lambda_min(S) > -eta with eta = eigenvalue_tolerance * max_i Q_ii (the
  /// largest diagonal entry of L_rho + Sigma): relative, so it means the same
  /// for graphs whose weights differ by orders of magnitude.
  double eigenvalue_tolerance = 1e-9;
  /// Minimum-eigenvalue iteration: stop when |S x - theta x| <=
  /// residual_tolerance * |theta| + eta (theta is then within that distance of
  /// an eigenvalue of S).
  double residual_tolerance = 1e-2;
  /// Inverse-iteration steps at most.
  int max_iterations = 200;
  /// Seed of the random start vectors (besides the rows of Y).
  uint64_t seed = 1;

  /// Throws std::invalid_argument naming the key that is out of range.
  void Validate() const;
};

struct SeSyncCertificate {
  bool certified = false;         ///< lambda_min(S) > -eta (proved by a Cholesky factorisation).
  double lambda_min = 0.0;        ///< Estimate of the minimum eigenvalue of S (a Ritz value).
  double lambda_lower = 0.0;      ///< Proved lower bound: lambda_min(S) > lambda_lower.
  double eta = 0.0;               ///< The absolute tolerance used.
  double relaxation_value = 0.0;  ///< tr(Y Q Y^T) = tr(Lambda): F with optimal translations.
  /// Lower bound on the global optimum F* from the relaxation's dual: certified,
  /// tr(Lambda) (Lambda is dual feasible to the tolerance eta, as SE-Sync
  /// reports it); otherwise tr(Lambda) + dn lambda_lower (Lambda +
  /// lambda_lower I is dual feasible, proved by a factorisation).
  double dual_bound = 0.0;
  /// F(x) - dual_bound for the F of the estimate x that was certified.
  double suboptimality_bound = 0.0;
  double gradient_norm = 0.0;       ///< |S Y^T|_F: zero at a critical point.
  int rank = 0;                     ///< r, rows of Y.
  int factorisations = 0;           ///< Sparse Cholesky factorisations of K(sigma).
  int iterations = 0;               ///< Inverse-iteration steps.
  double time_s = 0.0;              ///< Wall time of the certification.
  Eigen::VectorXd min_eigenvector;  ///< Unit vector (dn) of lambda_min.
};

/// The data matrices of SE-Sync's rotation-only problem for one graph (2D or
/// 3D; 2D graphs use the planar 2x2 rotations and 2-vectors), with the
/// factorisation of L_r cached. Vertex k of graph.vertices is block k.
class SeSyncRelaxation {
 public:
  /// Builds M's blocks from the edges' kappa, tau and measurements. Throws
  /// GraphError if the graph is not connected.
  explicit SeSyncRelaxation(const PoseGraph& graph);
  ~SeSyncRelaxation();
  SeSyncRelaxation(const SeSyncRelaxation&) = delete;
  SeSyncRelaxation& operator=(const SeSyncRelaxation&) = delete;

  int dimension() const { return d_; }
  int num_poses() const { return n_; }

  /// The vertex rotations of `graph` as Y (d x dn, Y_i = R_i).
  Eigen::MatrixXd Rotations(const PoseGraph& graph) const;

  /// Q X for X with dn rows (any number of columns).
  Eigen::MatrixXd QProduct(const Eigen::MatrixXd& X) const;

  /// F at Y with the translations optimal for Y: tr(Y Q Y^T).
  double Objective(const Eigen::MatrixXd& Y) const;

  /// The translations optimal for Y (r x n), vertex 0 at `t0` (r entries).
  Eigen::MatrixXd Translations(const Eigen::MatrixXd& Y, const Eigen::VectorXd& t0) const;

  /// The multiplier blocks Lambda_i = sym((Q Y^T)_i Y_i), side by side (d x dn),
  /// given Q Y^T.
  Eigen::MatrixXd LambdaBlocks(const Eigen::MatrixXd& Y, const Eigen::MatrixXd& QYt) const;

  /// Certificate of Y (r x dn, each block with orthonormal columns). F_estimate
  /// is the F of the estimate being certified (for the suboptimality bound);
  /// pass Objective(Y) if the translations are optimal.
  SeSyncCertificate Certify(const Eigen::MatrixXd& Y, double F_estimate,
                            const SeSyncCertificateOptions& options = {}) const;

 private:
  struct Factor;
  int d_ = 3;
  int n_ = 0;
  Eigen::SparseMatrix<double> rotation_block_;  // L_rho + Sigma (dn x dn).
  Eigen::SparseMatrix<double> coupling_;        // V_r ((n-1) x dn).
  Eigen::SparseMatrix<double> laplacian_;       // L_r ((n-1) x (n-1)).
  std::unique_ptr<Factor> laplacian_factor_;
};

/// Certificate of the vertex rotations of `graph` (rank d) for the SE-Sync
/// objective; F_estimate is SeSyncObjective(graph) (the translations as they
/// are). Throws GraphError if the graph is not connected.
SeSyncCertificate CertifySeSync(const PoseGraph& graph,
                                const SeSyncCertificateOptions& options = {});

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_GRAPH_SE_SYNC_CERTIFICATE_H_
