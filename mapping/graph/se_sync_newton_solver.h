#ifndef ROVER_MAPPING_GRAPH_SE_SYNC_NEWTON_SOLVER_H_
#define ROVER_MAPPING_GRAPH_SE_SYNC_NEWTON_SOLVER_H_

// Riemannian Newton trust-region solver for SE-Sync's objective F over
// SE(d)^n (d = 2, 3), first vertex fixed.
//
// Gauss-Newton (Ceres's LM) converges only linearly on F: its residuals do
// not vanish at the optimum, and the rotations' curvature term they multiply
// is what J^T J leaves out. That term is block diagonal: every residual is
// linear in the ambient (t, R), so the only second-order part comes from the
// retraction R Exp(phi) = R (I + [phi]x + [phi]x^2 / 2 + ...). With G_i the
// Euclidean gradient of F/2 with respect to R_i and Lambda_i = sym(R_i^T G_i)
// (the Lagrange multiplier of the certificate, se_sync_certificate.h), the
// exact Hessian of F/2 in the tangent coordinates [dt; dphi] is
//     H = J^T J + blockdiag(C_i),   C_i = Lambda_i - tr(Lambda_i) I (3D),
//                                    C_i = -tr(Lambda_i)              (2D),
// so Newton's method costs one sparse Cholesky (CHOLMOD) per iteration, like
// Gauss-Newton, and converges quadratically. Far from the optimum (where H
// may be indefinite) a Gauss-Newton step comes first. Steps are safeguarded by
// Levenberg-Marquardt damping mu diag(J^T J) (raised x10 on a rejected step,
// lowered x10 after a step whose decrease the model predicted well), which is
// zero while the full Newton steps are accepted.
//
// Residuals and Jacobians are ChordalPose3dCost / ChordalPose2dCost's, the
// parameterisation PoseManifold's (3D) or (x, y, theta) (2D).

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <functional>
#include <string>

#include "mapping/graph/pose_graph.h"

namespace rover::mapping {

struct SeSyncNewtonOptions {
  int max_iterations = 100;
  /// Stop after an accepted step that decreased F by less than
  /// function_tolerance * F (Newton: the next one would gain its square).
  double function_tolerance = 1e-10;
  /// Stop when the max-norm of the gradient of F/2 is below this.
  double gradient_tolerance = 1e-10;
  /// Gauss-Newton steps (J^T J, no curvature term) before the exact-Hessian
  /// steps: at the chordal start the exact Hessian may be indefinite and
  /// Gauss-Newton is the better model (iterations summed over the eight
  /// standard datasets: none 44, one 40, two 39).
  int gauss_newton_steps = 1;
  /// Called after every accepted step with (iteration, F/2, seconds since
  /// the solve started); may be empty.
  std::function<void(int, double, double)> progress;

  /// Throws std::invalid_argument naming the key that is out of range.
  void Validate() const;
};

struct SeSyncNewtonSummary {
  int iterations = 0;              ///< Accepted steps.
  int factorisations = 0;          ///< Sparse Cholesky factorisations (incl. rejected steps).
  double initial_cost = 0.0;       ///< F/2 at the start (Ceres's convention).
  double final_cost = 0.0;         ///< F/2 at the end.
  double gradient_max_norm = 0.0;  ///< Of F/2 in tangent coordinates, at the end.
  bool converged = false;          ///< A tolerance was met (not max_iterations).
  std::string message;             ///< Why it stopped.
};

/// Second-order model of F/2 at the graph's poses in the tangent coordinates
/// of vertices 1..n-1 ([dt; dphi] per vertex, PoseManifold's order in 3D,
/// (dx, dy, dtheta) in 2D): value, gradient and the Hessian (exact, or
/// Gauss-Newton's J^T J if `exact` is false), lower triangle plus full
/// diagonal blocks (read it through selfadjointView<Eigen::Lower>()).
struct SeSyncQuadraticModel {
  double cost = 0.0;
  Eigen::VectorXd gradient;
  Eigen::SparseMatrix<double> hessian;
};
SeSyncQuadraticModel SeSyncNewtonModel(const PoseGraph& graph, bool exact = true);

/// Minimises F over graph.vertices in place (first vertex fixed), starting
/// from the poses given. Throws GraphError for a gauge problem or NaN input
/// (CheckGaugeAndFinite).
SeSyncNewtonSummary SolveSeSyncNewton(PoseGraph& graph, const SeSyncNewtonOptions& options = {});

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_GRAPH_SE_SYNC_NEWTON_SOLVER_H_
