#ifndef ROVER_MAPPING_GRAPH_SYNTHETIC_SUBMAP_TRAJECTORY_H_
#define ROVER_MAPPING_GRAPH_SYNTHETIC_SUBMAP_TRAJECTORY_H_

// A seeded synthetic single-rover submap sequence for tests and benchmarks of
// RoverGraph's online updates: the rover wanders a bounded area over gentle
// terrain, starting a new gravity-aligned submap every `step_m`; each frame
// switch w is a noisy 4-DoF relative pose, each submap gets noisy filter poses
// v, and every `loop_every` submaps a submap match c links the new submap to a
// random earlier one within `loop_radius_m` (a revisit).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "mapping/graph/rover_graph.h"

namespace rover::mapping {

struct SyntheticSubmapTrajectoryOptions {
  int submaps = 1000;
  double step_m = 2.0;              ///< Travel between consecutive origins.
  double area_half_width_m = 40.0;  ///< The rover turns back at this |x| or |y|.
  int loop_every = 5;               ///< Submaps between loop-closure attempts.
  double loop_radius_m = 8.0;       ///< Match candidates lie within this distance.
  int min_loop_gap = 20;            ///< Matched submaps are at least this far apart in index.
  double w_sigma_p_m = 0.05;        ///< Frame switch translation noise (per axis).
  double w_sigma_yaw_rad = 0.005;   ///< Frame switch yaw noise.
  double c_sigma_p_m = 0.05;        ///< Submap match translation noise (per axis).
  double c_sigma_rot_rad = 0.005;   ///< Submap match rotation noise (per axis).
  int filter_poses_per_submap = 1;  ///< v factors per submap.
};

struct SyntheticLoop {
  int64_t submap_a = 0;
  int64_t submap_b = 0;
  Eigen::Isometry3d T_a_b = Eigen::Isometry3d::Identity();
  Matrix6d covariance = Matrix6d::Identity();
};

/// The factors that arrive with submap `submap` (its frame switch from
/// submap - 1, its filter poses, the loop closures found for it).
struct SyntheticSubmapStep {
  int64_t submap = 0;
  Eigen::Isometry3d T_old_new = Eigen::Isometry3d::Identity();
  Matrix4d w_covariance = Matrix4d::Identity();
  std::vector<Eigen::Isometry3d> T_local_body;
  std::vector<Matrix6d> v_covariance;
  std::vector<SyntheticLoop> loops;
};

struct SyntheticSubmapTrajectory {
  std::vector<Eigen::Isometry3d> T_world_origin;  ///< Ground truth, one per submap.
  Matrix6d prior_covariance = Matrix6d::Identity();
  std::vector<SyntheticSubmapStep> steps;  ///< steps[i] creates submap i + 1.

  /// The prior on s0_0 at its true pose.
  void AddPrior(RoverGraph* graph) const;
  /// Adds the factors of steps[i] (robot 0); returns the number of loops.
  int AddStep(size_t i, RoverGraph* graph) const;
  int LoopCount() const;
};

/// Builds the sequence; identical for identical (options, seed).
SyntheticSubmapTrajectory MakeSyntheticSubmapTrajectory(
    const SyntheticSubmapTrajectoryOptions& options, uint32_t seed);

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_GRAPH_SYNTHETIC_SUBMAP_TRAJECTORY_H_
