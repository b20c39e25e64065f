#ifndef ROVER_MAPPING_LOOP_SUBMAP_ICP_H_
#define ROVER_MAPPING_LOOP_SUBMAP_ICP_H_

// The matcher's refinement (thesis section 6.1.2): ICP between two submaps'
// full clouds, b's subsample (SubmapMatchData::icp_points) against a's
// cloud, Gauss-Newton on a left perturbation T_a_b <- Exp(delta) T_a_b.
// In 4D (the thesis's method) delta = (dx, dy, dz, dyaw): roll and pitch
// are never touched, so the optimiser cannot drift into the tilted minima
// that a 6D ICP finds and the plausibility check then throws away; in 6D
// (the baseline) delta is a full twist.
//
// Correspondences: nearest neighbour within a distance that starts at
// initial_distance_m and shrinks by 0.7 per iteration to final_distance_m
// (a wide basin first, outliers cut at the end).
//
// Covariance: the Gauss-Newton Hessian H = sum J^T J of the last
// iteration, scaled by the residual variance s^2 = sum r^2 / (N - dof):
// Sigma = s^2 H^-1, converted to the rover graph's convention
// [dp (frame a); dtheta (right)]. It treats residuals as independent, which
// neighbouring stereo points are not, so the matcher floors it.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "mapping/graph/pose_graph.h"
#include "mapping/loop/submap_match_data.h"

namespace rover::mapping {

enum class IcpMetric { kPointToPlane, kPointToPoint };

struct SubmapIcpOptions {
  IcpMetric metric = IcpMetric::kPointToPlane;
  int max_iterations = 40;
  double initial_distance_m = 0.5;
  double final_distance_m = 0.15;
  /// Converged when a step moves less than this (translation, and rotation
  /// in rad) once the distance has reached final_distance_m.
  double convergence_m = 1e-3;
  double convergence_rad = 1e-4;
  /// Cauchy weights w = 1 / (1 + (r / c)^2) on the residuals (iteratively
  /// reweighted). c anneals like the correspondence distance, from half the
  /// initial distance down to robust_scale_m: a small c from the start would
  /// narrow the basin the RANSAC hypothesis has to land in; at the end it
  /// stops the residuals of surfaces only one submap saw well (other sides
  /// of rocks, stereo fringes) from pulling the result off by a decimetre.
  /// 0: plain least squares within the correspondence distance.
  double robust_scale_m = 0.0;
  /// Fewer correspondences than this: the ICP fails.
  int min_correspondences = 100;
  /// A pair whose normals (both pointing to their free side) differ by more
  /// than this is not a correspondence: a rock's front against its back.
  /// 180 deg disables the test.
  double max_normal_angle_deg = 60.0;
  /// Obstacle agreement at the result: b's obstacle points with an a point
  /// within this distance, and how many of those a point is an obstacle.
  double obstacle_agreement_distance_m = 0.15;

  /// Throws std::invalid_argument "SubmapIcpOptions.<key>: ...".
  void Validate() const;
};

struct SubmapIcpResult {
  bool ok = false;  ///< false: too few correspondences or a degenerate Hessian
  Eigen::Isometry3d T_a_b = Eigen::Isometry3d::Identity();
  /// s^2 H^-1 in [dp (frame a); dtheta (right)]. In 4D, roll and pitch rows
  /// and columns are zero.
  Matrix6d covariance = Matrix6d::Zero();
  int iterations = 0;
  bool converged = false;
  /// Of the last iteration (within final_distance_m).
  int correspondences = 0;
  /// RMS of the residuals of `metric` in the last iteration.
  double rmse_m = 0.0;
  /// RMS point-to-point distance of the same correspondences (the thesis's
  /// figure).
  double point_rmse_m = 0.0;
  /// Source points that had a target within final_distance_m, and the source
  /// points considered (those within the target's box).
  int overlap_points = 0;
  int source_points = 0;
  /// b's obstacle points (ICP subsample) with an a point nearby at the
  /// result, and of those the ones whose nearest a point is an obstacle
  /// too: a false alignment lays rocks on ground.
  int obstacle_points_near = 0;
  int obstacle_points_agreeing = 0;
};

/// Refines T_a_b from `initial`. `four_dof` selects x, y, z, yaw only.
SubmapIcpResult AlignSubmaps(const SubmapMatchData& a, const SubmapMatchData& b,
                             const Eigen::Isometry3d& initial, bool four_dof,
                             const SubmapIcpOptions& options);

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_LOOP_SUBMAP_ICP_H_
