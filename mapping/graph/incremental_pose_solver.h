#ifndef ROVER_MAPPING_GRAPH_INCREMENTAL_POSE_SOLVER_H_
#define ROVER_MAPPING_GRAPH_INCREMENTAL_POSE_SOLVER_H_

// Incremental Gauss-Newton on SE(3) pose graphs (after iSAM2's fluid
// relinearisation, Kaess et al. 2012, on a block Cholesky factor instead of a
// Bayes tree). Every variable keeps a linearisation point theta and a step
// delta (estimate = theta (+) delta); every factor keeps its whitened Jacobian
// blocks and residual at the theta of its variables (the same
// RelativePose3dCost / PosePrior3dCost as the Ceres problem). An update
//   - linearises the new factors,
//   - re-factors only the block columns of L (H = L L^T, 6x6 blocks, fixed
//     ordering) that the change reaches: the changed columns and their
//     ancestors in the elimination tree,
//   - solves for delta, relinearises only the variables whose delta exceeds a
//     threshold (and their factors), and repeats until none does (or for a
//     fixed number of steps, iSAM2's one per update; see steps_per_update).
// The ordering is Eigen's approximate minimum degree on the older variables
// with the newest ones last (as iSAM2 constrains CCOLAMD: new factors touch
// them, and their columns near the root have few ancestors); variables added
// later are appended, and the graph is re-ordered every `reorder_interval` of
// them.
// Robust (Cauchy) factors contribute the exact Hessian of 1/2 rho(|r|^2),
// J^T (rho' I + 2 rho'' r r^T) J, and the gradient rho' J^T r: the same
// stationary points as Ceres's robustified cost, reached in a few Newton steps
// where plain reweighting (rho' J^T J) converges linearly. If the negative
// curvature of a factor in the concave part of rho makes H indefinite, that
// term is floored at 0 until the next re-ordering.
// Marginal covariances come from a forward solve along one column's path to
// the root of the elimination tree: Sigma_vv = Y^T Y, Y = L^-1 E_v.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <memory>
#include <vector>

namespace rover::mapping {

struct IncrementalPoseSolverOptions {
  /// A variable is relinearised when the rotation part of its step exceeds
  /// this [rad] in any component, or the translation part
  /// relinearize_translation_m [m]. Both 0 (with reorder_interval 0): every
  /// variable and every column, every iteration (batch Gauss-Newton).
  double relinearize_rotation_rad = 5e-4;
  double relinearize_translation_m = 5e-4;
  /// Both variables of a robust factor are relinearised when its weight rho'
  /// at the predicted residual differs from the linearised one by more than
  /// this fraction.
  double robust_weight_tolerance = 0.05;
  /// Steps below this (any unit) never trigger relinearisation.
  double step_tolerance = 1e-6;
  int max_iterations = 10;
  /// Gauss-Newton steps per Update(): 0 iterates until converged (at most
  /// max_iterations); 1 is iSAM2's one step per update, the rest of the
  /// convergence left to the next updates (or Converge()).
  int steps_per_update = 0;
  /// New variables appended at the end of the ordering before the graph is
  /// re-ordered (full re-factorisation). 0: re-order and re-factor everything
  /// at every update (batch).
  int reorder_interval = 100;
  /// Cauchy scale c of robust factors (Mahalanobis units).
  double cauchy_scale = 2.0;
};

struct IncrementalPoseSolverStats {
  int iterations = 0;
  int relinearized_variables = 0;
  int refactored_columns = 0;
  bool reordered = false;
  bool converged = false;
  /// Times the exact robust curvature made H indefinite and was floored.
  int floored_robust_hessian = 0;
};

class IncrementalPoseSolver {
 public:
  using Matrix6d = Eigen::Matrix<double, 6, 6>;

  explicit IncrementalPoseSolver(const IncrementalPoseSolverOptions& options);
  ~IncrementalPoseSolver();

  /// Adds a variable with linearisation point x = [t; q_xyzw]; returns its index.
  int AddVariable(const double* x);

  /// Adds a relative factor T_a_b between variables a and b (b = -1: a prior
  /// T_world_a) with its information over the RelativePose3dCost error.
  void AddFactor(int a, int b, const Eigen::Isometry3d& Z, const Matrix6d& information,
                 bool robust);

  /// Gauss-Newton with fluid relinearisation: options.steps_per_update
  /// steps, or (0) until converged or max_iterations. Each step relinearises
  /// what the previous one moved beyond the thresholds (the first: what the
  /// last update left). Throws std::runtime_error if the system is singular.
  IncrementalPoseSolverStats Update();

  /// Steps until converged or max_iterations (after one-step updates).
  IncrementalPoseSolverStats Converge();

  /// True when the next Update() re-orders the graph and re-factors all of
  /// it (reorder_interval variables appended since the last re-ordering).
  bool ReorderDue() const;

  /// Current estimate theta (+) delta of variable v into x (7 doubles).
  void Estimate(int v, double* x) const;

  /// Scales every variable's pending step delta by alpha (a backtracking
  /// line search by the caller, who knows the true cost): the estimate
  /// becomes theta (+) alpha delta, and the next Update() carries on from it.
  void ScaleStep(double alpha);

  /// Resets every linearisation point to x_of[v] (e.g. after an external
  /// solve): all factors are relinearised and the graph re-ordered at the
  /// next Update().
  void ResetLinearization(const std::vector<const double*>& x_of);

  /// Marginal covariance of variable v over [dt (world); dphi (right)] from the
  /// current factor (call after Update()). Costs one sparse forward solve
  /// along v's path to the root of the elimination tree.
  Matrix6d MarginalCovariance(int v) const;

  /// Variables within `hops` factors of `seeds` (including the seeds).
  std::vector<int> Neighbourhood(const std::vector<int>& seeds, int hops) const;

  int num_variables() const;

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_GRAPH_INCREMENTAL_POSE_SOLVER_H_
