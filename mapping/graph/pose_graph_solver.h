#ifndef ROVER_MAPPING_GRAPH_POSE_GRAPH_SOLVER_H_
#define ROVER_MAPPING_GRAPH_POSE_GRAPH_SOLVER_H_

// Batch solver for g2o pose graphs (2D and 3D) on Ceres: initialisation
// (chordal or odometry), nonlinear refinement of either objective with
// analytic Jacobians, optional robust handling of loop closures (Cauchy loss,
// graduated non-convexity), and the figures to compare with published results.

#include <functional>
#include <string>
#include <vector>

#include "core/config/config.h"
#include "mapping/graph/pose_graph.h"

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
  /// GNC: an edge whose squared residual exceeds this is an outlier at the
  /// end of the schedule (barc^2 of Yang et al. 2020).
  double gnc_threshold = 100.0;
  /// GNC: mu is divided by this factor per step until it reaches 1.
  double gnc_step = 1.4;
  /// Trust-region strategy: Levenberg-Marquardt (false) or Powell's dog leg (true).
  bool dogleg = false;
  /// Initial trust-region radius (Ceres: 1 / initial LM damping).
  double initial_trust_region_radius = 1e4;
  int max_iterations = 200;
  int num_threads = 2;
  /// Ceres stopping criteria (relative cost decrease, gradient max-norm,
  /// relative step size).
  double function_tolerance = 1e-6;
  double gradient_tolerance = 1e-10;
  double parameter_tolerance = 1e-8;
  /// Called once per Ceres iteration with (iteration, cost, seconds since the
  /// solve started); may be empty.
  std::function<void(int, double, double)> progress;

  /// Reads keys objective (chi2|sesync), initialisation (chordal|odometry|file),
  /// outliers (none|cauchy|gnc), trust_region (lm|dogleg),
  /// initial_trust_region_radius, cauchy_scale, gnc_threshold, gnc_step,
  /// max_iterations, num_threads, function_tolerance, gradient_tolerance,
  /// parameter_tolerance; every key is optional.
  static PoseGraphSolverOptions Load(const ConfigNode& node);
};

struct PoseGraphSolverSummary {
  int iterations = 0;         ///< Ceres iterations (summed over GNC steps).
  double init_time_s = 0.0;   ///< Initialisation wall time.
  double solve_time_s = 0.0;  ///< Nonlinear refinement wall time.
  double total_time_s = 0.0;  ///< Both.
  double initial_cost = 0.0;  ///< Ceres cost (0.5 sum rho(|r|^2)) after init.
  double final_cost = 0.0;    ///< Ceres cost at the end.
  double F = 0.0;             ///< SE-Sync objective at the solution (all edges).
  double chi2 = 0.0;          ///< g2o chi2 at the solution (all edges).
  bool converged = false;     ///< Ceres reported convergence.
  int loop_closures = 0;      ///< Edges with |to - from| != 1.
  int rejected = 0;           ///< Loop closures classified as outliers.
  std::vector<bool> inlier;   ///< Per edge: kept (true) or rejected.
  std::string message;        ///< Ceres termination message.
};

/// Optimises the vertex poses of `graph` in place. The first vertex is held
/// fixed (gauge). Throws GraphError for a gauge problem (several connected
/// components) or NaN input, naming the vertices involved.
PoseGraphSolverSummary SolvePoseGraph(PoseGraph& graph, const PoseGraphSolverOptions& options);

/// GNC initialisation used by OutlierHandling::kGnc: graduated
/// non-convexity (Geman-McClure) over loop closures, each step a weighted
/// chordal initialisation; then a chordal solve on the kept edges. Writes the
/// vertices and returns, per edge, whether it was kept.
std::vector<bool> RobustChordalInitialisation(PoseGraph& graph,
                                              const PoseGraphSolverOptions& options);

/// Loop closure: an edge between vertices whose ids are not consecutive.
bool IsLoopClosure(const PoseEdge& edge);

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_GRAPH_POSE_GRAPH_SOLVER_H_
