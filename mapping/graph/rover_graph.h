#ifndef ROVER_MAPPING_GRAPH_ROVER_GRAPH_H_
#define ROVER_MAPPING_GRAPH_ROVER_GRAPH_H_

// The rover's multi-robot SLAM graph on SE(3) with the thesis's
// local-reference topology (Schuster et al. 2015): submap origins s^r_i (the
// filter's gravity-aligned local frames), sparse robot poses x^r_i and
// landmarks l_i, connected by
//   prior  one per robot, on its first origin;
//   w      frame switch s_i -> s_i+1 (4-DoF, from the filter);
//   v      filter pose in its local frame, s_j -> x;
//   c      submap match between two origins (same or different robots);
//   d      robot detection between two robots' poses at the same time;
//   o      landmark observation, x -> l.
// A Cauchy loss applies to c, d and o only. Factors may be added in any
// order (late ones included); Optimize() warm-starts from the previous
// solution, initialises new variables by composing factors from anchored
// ones, and then computes the marginal covariances of all submap origins.
//
// Covariance inputs are over [dp; dtheta] (translation first) with
//   p_true = p_est + dp  (dp in the measurement's reference frame a of T_a_b)
//   R_true = R_est * Exp(dtheta)  (right, body-side perturbation),
// the filter's convention; see mapping/graph/README.md for the exact
// conversion to the residuals' information matrices.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/config/config.h"
#include "mapping/graph/graph_key.h"
#include "mapping/graph/pose_graph.h"

namespace rover::mapping {

using Matrix4d = Eigen::Matrix4d;

struct RoverGraphOptions {
  /// Cauchy scale c on c, d and o factors, in units of the Mahalanobis
  /// distance: rho(s) = c^2 log(1 + s / c^2).
  double cauchy_scale = 2.0;
  /// Standard deviation [rad] of the stiff prior that keeps the relative
  /// rotation of a frame switch about z only (both frames are gravity-aligned).
  double frame_switch_roll_pitch_sigma_rad = 1e-4;
  int max_iterations = 100;
  int num_threads = 2;
  /// Compute the origin marginals after each Optimize().
  bool compute_origin_covariances = true;
  /// Skip the solve when the new factors only hang new variables off the
  /// graph (odometry extending a chain, a new filter pose): composing them is
  /// then the exact optimum, and new origin marginals are propagated.
  bool incremental = true;
  /// With `incremental`: updates that close loops run the incremental
  /// Gauss-Newton (IncrementalPoseSolver: fluid relinearisation, partial
  /// re-factorisation) instead of a full Ceres solve; the first solve and a
  /// non-converged update fall back to Ceres.
  bool incremental_solve = true;
  /// Rotation step [rad] and translation step [m] above which the
  /// incremental solver relinearises a variable (IncrementalPoseSolverOptions).
  /// Both 0: every variable every iteration (batch Gauss-Newton).
  double relinearize_rotation_rad = 5e-4;
  double relinearize_translation_m = 5e-4;
  /// New variables appended to the elimination ordering before it is
  /// recomputed (a full re-factorisation). 0: every update (batch).
  int reorder_interval = 100;
  /// After an incremental solve, the origin marginals within this many factor
  /// hops of the new factors' variables are recomputed; the others keep their
  /// last value (an upper bound to first order: factors only add
  /// information). -1: all origins.
  int covariance_hops = 2;
  /// Gauss-Newton steps per incremental update: 0 iterates to convergence
  /// (Ceres fallback if it does not); 1 is iSAM2's single step, leaving the
  /// rest of the convergence to the next updates.
  int incremental_steps = 0;

  /// Throws std::invalid_argument naming the first out-of-range key.
  void Validate() const;

  /// The online settings mapd runs, iSAM2's way: one Gauss-Newton step per
  /// update and the rest of the convergence in the graph thread's idle time
  /// (Refine), relinearising variables that moved more than 2 mrad or 5 mm
  /// (about 1 mm from the exact optimum at 1000 submaps, bench_graph_update).
  /// The defaults above converge every update instead (offline tools).
  static RoverGraphOptions Online();

  /// Keys: cauchy_scale, frame_switch_roll_pitch_sigma_rad, max_iterations,
  /// num_threads, compute_origin_covariances, incremental, incremental_solve,
  /// relinearize_rotation_rad, relinearize_translation_m, reorder_interval,
  /// covariance_hops, incremental_steps (all optional).
  static RoverGraphOptions Load(const ConfigNode& node);
};

/// A robot detection d: robot `observer` sees the marker of robot `target`.
struct RobotDetection {
  Eigen::Isometry3d T_body_cam;     ///< Observer's camera extrinsic.
  Eigen::Isometry3d T_cam_marker;   ///< Detector's marker pose estimate.
  Matrix6d covariance_cam_marker;   ///< Of T_cam_marker, [dp; dtheta] convention.
  Eigen::Isometry3d T_body_marker;  ///< Target's marker mount.
};

/// d measurement T_body0_body1 = T_body_cam * T_cam_marker * T_body_marker^-1
/// and its covariance, propagated with the exact first-order Jacobian.
std::pair<Eigen::Isometry3d, Matrix6d> ComposeDetection(const RobotDetection& d);

/// Information of the RelativePose3dCost error for a measurement T_a_b whose
/// uncertainty is `covariance` over [dp (frame a); dtheta (right)]:
/// Omega = (J Sigma J^T)^-1 with J = diag(R_a_b^T, I / 2).
Matrix6d InformationFromCovariance(const Eigen::Isometry3d& T_a_b, const Matrix6d& covariance);

struct RoverGraphSummary {
  int iterations = 0;
  double initial_cost = 0.0;
  double final_cost = 0.0;
  double solve_time_s = 0.0;
  double covariance_time_s = 0.0;
  int variables = 0;
  int factors = 0;
  bool converged = false;
  /// False when the update only extended the graph (no solve was needed).
  bool solved = false;
  /// True when the solve was the incremental one (options.incremental_solve).
  bool incremental_solve = false;
  /// Incremental solve: variables relinearised and block columns of the
  /// factor recomputed (of `variables`), origin marginals recomputed.
  int relinearized = 0;
  int refactored_columns = 0;
  int covariances_updated = 0;
  /// The incremental solver re-ordered the graph and re-factored all of it
  /// (every reorder_interval new variables, on an update that only extends
  /// the graph when one is due).
  bool reordered = false;
  /// Variables no prior reaches (e.g. a robot not yet linked to the team, or
  /// a chain broken by a refused factor): left out of the solve, with their
  /// factors, until a factor connects them.
  std::vector<GraphKey> unanchored;
  /// Why the origins' marginals could not be computed this time (e.g. a
  /// rank-deficient problem); empty if they were. The solve stands, and the
  /// previous marginals are kept.
  std::string covariance_error;
};

class RoverGraph {
 public:
  explicit RoverGraph(const RoverGraphOptions& options = {});
  ~RoverGraph();
  RoverGraph(const RoverGraph&) = delete;
  RoverGraph& operator=(const RoverGraph&) = delete;

  /// Prior on robot `robot`'s first origin s^r_0: T_world_origin with its
  /// covariance ([dp in world; dtheta right]).
  void AddOriginPrior(int robot, const Eigen::Isometry3d& T_world_origin,
                      const Matrix6d& covariance);

  /// w: frame switch s^r_submap -> s^r_(submap+1). T_old_new must rotate about
  /// z only; `covariance` (4x4) is over [dp (old frame); dyaw], with
  /// p_true = p_est + dp and yaw_true = yaw_est + dyaw. Roll and pitch of the
  /// relative rotation get a stiff prior (options.frame_switch_roll_pitch_sigma_rad).
  void AddFrameSwitch(int robot, int64_t submap, const Eigen::Isometry3d& T_old_new,
                      const Matrix4d& covariance);

  /// v: filter estimate T_local_body of pose x^r_pose in the local frame of
  /// submap s^r_submap, with the filter's 6x6 covariance.
  void AddFilterPose(int robot, int64_t submap, int64_t pose, const Eigen::Isometry3d& T_local_body,
                     const Matrix6d& covariance);

  /// c: submap match T_a_b between origins s^robot_a_submap_a and
  /// s^robot_b_submap_b (intra- or inter-robot loop closure). Robust.
  void AddSubmapMatch(int robot_a, int64_t submap_a, int robot_b, int64_t submap_b,
                      const Eigen::Isometry3d& T_a_b, const Matrix6d& covariance);

  /// d: robot `observer` at pose index `observer_pose` detects robot `target`
  /// at `target_pose` (the same time). Robust.
  void AddRobotDetection(int observer, int64_t observer_pose, int target, int64_t target_pose,
                         const RobotDetection& detection);

  /// o: robot pose x^r_pose observes landmark l_id at T_body_landmark. Robust.
  void AddLandmarkObservation(int robot, int64_t pose, int64_t landmark,
                              const Eigen::Isometry3d& T_body_landmark, const Matrix6d& covariance);

  /// Generic factors (used by the baselines and tests): a prior on `key`, and
  /// a relative pose T_a_b between `a` and `b`, same covariance convention.
  void AddPrior(const GraphKey& key, const Eigen::Isometry3d& T_world_key,
                const Matrix6d& covariance);
  void AddBetween(const GraphKey& a, const GraphKey& b, const Eigen::Isometry3d& T_a_b,
                  const Matrix6d& covariance, bool robust);

  /// Latest filter output of `robot`, kept outside the graph: GlobalPose().
  void SetCurrentFilterPose(int robot, int64_t submap, const Eigen::Isometry3d& T_local_body);

  /// Adds the factors received since the last call, initialises new
  /// variables, optimises (warm-started) and, if enabled, computes the origin
  /// marginals. With options.incremental, factors that only extend the graph
  /// by new variables (no loop) are composed without a solve. Variables that
  /// no prior reaches wait outside the solve (summary.unanchored names them).
  /// Throws GraphError if the graph has no prior at all.
  RoverGraphSummary Optimize();

  /// True after a one-step update (options.incremental_steps > 0) that did
  /// not converge, until Refine() converges (after 20 steps, or
  /// max_iterations if fewer, it hands the graph to Ceres, as a converging
  /// update does).
  bool NeedsRefinement() const;
  /// One more incremental Gauss-Newton step on the factors already added
  /// (iSAM2's update without new factors), for when the caller is idle: the
  /// estimates move on towards the optimum a loop closure's one-step update
  /// left them short of. Origin marginals keep the values of the last
  /// Optimize(). Returns a converged summary without work when no step is
  /// due. Factors added since the last Optimize() are not included.
  RoverGraphSummary Refine();

  /// Current estimate of a variable (T_world_key). Throws GraphError if the
  /// variable does not exist or has not been optimised yet.
  Eigen::Isometry3d Estimate(const GraphKey& key) const;
  Eigen::Isometry3d Origin(int robot, int64_t submap) const {
    return Estimate(GraphKey::Origin(robot, submap));
  }

  /// Marginal covariance of origin s^r_submap from the last Optimize(), in
  /// the PoseManifold tangent [dt (world); dphi (right)]. Throws GraphError if
  /// unavailable.
  Matrix6d OriginCovariance(int robot, int64_t submap) const;

  /// Current global pose of `robot`: s_j (+) v_t = Origin(j) * T_local_body of
  /// the latest SetCurrentFilterPose (or, if none, of its latest v factor).
  Eigen::Isometry3d GlobalPose(int robot) const;

  /// All variables currently in the graph.
  std::vector<GraphKey> Keys() const;

 private:
  struct Variable;
  struct Factor;
  class Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_GRAPH_ROVER_GRAPH_H_
