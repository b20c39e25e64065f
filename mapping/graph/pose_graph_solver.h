#ifndef ROVER_MAPPING_GRAPH_POSE_GRAPH_SOLVER_H_
#define ROVER_MAPPING_GRAPH_POSE_GRAPH_SOLVER_H_

// Batch solver for g2o pose graphs (2D and 3D) on Ceres: initialisation
// (chordal or odometry), nonlinear refinement of either objective with
// analytic Jacobians, optional robust handling of loop closures (Cauchy loss,
// graduated non-convexity), and the figures to compare with published results.

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "core/config/config.h"
#include "mapping/graph/pose_graph.h"
#include "mapping/graph/se_sync_certificate.h"

namespace rover::mapping {

enum class Objective {
  kChi2,    ///< g2o's full-information objective (what the rover graph uses).
  kSeSync,  ///< SE-Sync's isotropic objective F.
};

enum class Initialisation {
  kChordal,   ///< Chordal relaxation for rotations, then linear translations.
  kOdometry,  ///< Compose measurements along a spanning tree (odometry first).
  kFile,      ///< Use the vertex poses as given (odometry for vertex-less files).
};

enum class OutlierHandling {
  kNone,    ///< Plain least squares on every edge.
  kCauchy,  ///< Cauchy loss (scale `cauchy_scale`) on loop closures.
  kGnc,     ///< Graduated non-convexity (Geman-McClure) on loop closures, then a
            ///< least-squares refinement on the edges it kept.
};

struct PoseGraphSolverOptions {
  Objective objective = Objective::kChi2;
  Initialisation initialisation = Initialisation::kChordal;
  OutlierHandling outliers = OutlierHandling::kNone;
  /// Cauchy scale c: residuals with |r| well above c are down-weighted
  /// (rho(s) = c^2 log(1 + s / c^2), s = |r|^2).
  double cauchy_scale = 1.0;
  /// GNC: a loop closure whose F term (squared residual) exceeds this is an
  /// outlier (barc^2 of Yang et al. 2020). 0: derived from
  /// `outlier_confidence` (InlierThreshold: 32.5 in 2D, 89.8 in 3D at 0.999).
  /// The default 100 is what passes manhattan 10 % / 30 % (32.5 loses true
  /// loops there); see README.
  double gnc_threshold = 100.0;
  /// GNC: probability that an inlier's F term stays below the threshold under
  /// the edge's noise model (see InlierThreshold).
  double outlier_confidence = 0.999;
  /// GNC: mu is divided by this factor per step until it reaches 1.
  double gnc_step = 1.4;
  /// Trust-region strategy: Levenberg-Marquardt (false) or Powell's dog leg (true).
  bool dogleg = false;
  /// Initial trust-region radius (Ceres: 1 / initial LM damping). Large:
  /// from the chordal start the first steps are essentially Gauss-Newton
  /// (sphere2500 chi2: 3 iterations instead of 11 with Ceres's 1e4).
  double initial_trust_region_radius = 1e12;
  /// Sparse Cholesky library: SuiteSparse (CHOLMOD, supernodal) if Ceres has
  /// it, else Eigen; `eigen_sparse` forces Eigen's simplicial LDLT.
  bool eigen_sparse = false;
  /// Ceres's Jacobi column scaling of the linear system.
  bool jacobi_scaling = true;
  int max_iterations = 200;
  int num_threads = 2;
  /// Ceres stopping criteria (relative cost decrease, gradient max-norm,
  /// relative step size).
  double function_tolerance = 1e-6;
  double gradient_tolerance = 1e-10;
  double parameter_tolerance = 1e-8;
  /// SE-Sync objective without outlier handling: refine with the exact-Hessian
  /// Newton solver (se_sync_newton_solver.h; quadratic convergence) instead
  /// of Ceres's Gauss-Newton LM (linear convergence on F).
  bool newton = true;
  /// SE-Sync objective without outlier handling: compute SE-Sync's
  /// optimality certificate of the solution (se_sync_certificate.h).
  bool certify = true;
  SeSyncCertificateOptions certificate;
  /// If the certificate fails: climb SE-Sync's Riemannian staircase
  /// (se_sync_staircase.h), round, refine with Newton and certify again.
  bool staircase = true;
  /// Called once per Ceres iteration with (iteration, cost, seconds since the
  /// solve started); may be empty.
  std::function<void(int, double, double)> progress;

  /// Reads keys objective (chi2|sesync), initialisation (chordal|odometry|file),
  /// outliers (none|cauchy|gnc), trust_region (lm|dogleg),
  /// sesync_solver (newton|ceres), certify (true|false), staircase (true|false),
  /// initial_trust_region_radius, cauchy_scale, gnc_threshold,
  /// outlier_confidence, gnc_step, sparse_library (auto|eigen),
  /// jacobi_scaling (true|false),
  /// max_iterations, num_threads, function_tolerance, gradient_tolerance,
  /// parameter_tolerance; every key is optional.
  static PoseGraphSolverOptions Load(const ConfigNode& node);
};

/// What an objective leaves unused of the edges' information matrices.
struct InformationUse {
  /// Edges whose rotation-translation off-diagonal block is non-zero. The
  /// SE-Sync objective reads only the diagonal blocks (kappa from the rotation
  /// block, tau from the translation block, as SE-Sync does) and ignores it.
  int off_diagonal_ignored = 0;
  /// Of those, the edges whose matrix is indefinite as a whole (its diagonal
  /// blocks are positive definite: the reader checks them).
  int indefinite = 0;
  /// Source line of the first indefinite edge (0 if none or not from a file).
  int first_indefinite_line = 0;

  /// "" if nothing is ignored, else e.g. "12 edges: off-diagonal blocks
  /// ignored; 3 of them: info matrix indefinite as a whole (first on line 40)".
  std::string Describe() const;
};

/// Checks every edge's information matrix against what `objective` uses.
/// chi2 weights the whole matrix, so it must be positive definite: throws
/// GraphError "FILE:LINE: edge I -> J: expected a positive-definite
/// information matrix for the chi2 objective, found smallest eigenvalue X"
/// for the first edge that is not (with the count of the others). sesync uses
/// only the diagonal blocks: returns what it ignores, never throws.
InformationUse CheckInformation(const PoseGraph& graph, Objective objective);

struct PoseGraphSolverSummary {
  int iterations = 0;          ///< Ceres iterations (summed over GNC steps).
  double init_time_s = 0.0;    ///< Initialisation wall time.
  double solve_time_s = 0.0;   ///< Nonlinear refinement wall time.
  double total_time_s = 0.0;   ///< Both.
  double initial_cost = 0.0;   ///< Ceres cost (0.5 sum rho(|r|^2)) after init.
  double final_cost = 0.0;     ///< Ceres cost at the end.
  double F = 0.0;              ///< SE-Sync objective at the solution (all edges).
  double chi2 = 0.0;           ///< g2o chi2 at the solution (all edges).
  bool converged = false;      ///< Ceres reported convergence.
  int loop_closures = 0;       ///< Edges with |to - from| != 1.
  int rejected = 0;            ///< Loop closures classified as outliers.
  std::vector<bool> inlier;    ///< Per edge: kept (true) or rejected.
  std::string message;         ///< Ceres termination message.
  InformationUse information;  ///< What the objective ignored of the information matrices.
  /// SE-Sync's certificate of the solution (objective sesync, no outlier
  /// handling, `certify`); its time is part of total_time_s.
  std::optional<SeSyncCertificate> certificate;
  /// Riemannian staircase (the rank-d certificate failed): highest rank
  /// climbed (0: not needed) and its gradient steps; `certificate` is then
  /// that of the refined rounded solution.
  int staircase_rank = 0;
  int staircase_iterations = 0;
};

/// Optimises the vertex poses of `graph` in place. The first vertex is held
/// fixed (gauge). Throws GraphError for a gauge problem (several connected
/// components) or NaN input, naming the vertices involved, and for an
/// information matrix the objective cannot use (CheckInformation).
PoseGraphSolverSummary SolvePoseGraph(PoseGraph& graph, const PoseGraphSolverOptions& options);

/// GNC initialisation used by OutlierHandling::kGnc: graduated
/// non-convexity (Geman-McClure) over loop closures, each step a weighted
/// chordal initialisation (odometry edges keep weight 1); then a chordal solve
/// on the kept edges. Writes the vertices and returns, per edge, whether it
/// was kept. `steps` (optional) receives the number of chordal solves.
std::vector<bool> RobustChordalInitialisation(PoseGraph& graph,
                                              const PoseGraphSolverOptions& options,
                                              int* steps = nullptr);

/// Quantile of the chi-squared distribution with `dof` degrees of freedom:
/// the x with P(chi2_dof <= x) = p, p in (0, 1) (stats::Chi2Quantile).
double ChiSquaredQuantile(int dof, double p);

/// Bound on an inlier's F term at confidence p. If the edge noise follows its
/// information matrix, the F term is a weighted sum of chi-squared(1) variables
/// (2D: 2 chi2_1(rotation) + chi2_2(translation); 3D: 4 chi2_3 + chi2_3, the
/// factor 4 because g2o's rotation information is over half the angle), so it
/// is at most w_max chi2_d with d = 3 (2D) or 6 (3D), w_max = 2 (2D) or 4 (3D):
/// returns w_max * ChiSquaredQuantile(d, p).
double InlierThreshold(int dimension, double confidence);

/// Loop closure: an edge between vertices whose ids are not consecutive.
bool IsLoopClosure(const PoseEdge& edge);

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_GRAPH_POSE_GRAPH_SOLVER_H_
