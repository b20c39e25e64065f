#ifndef ROVER_MAPPING_GRAPH_SEQUENTIAL_ODOMETRY_GRAPH_H_
#define ROVER_MAPPING_GRAPH_SEQUENTIAL_ODOMETRY_GRAPH_H_

// Ablation baseline: the thesis's older "sequential odometry" topology
// (Brand et al. 2015). Robot poses x_k are chained by odometry-like factors
//   u_k = x_k^-1 * x_k+1   (from consecutive filter estimates),
//   Sigma_u = max(Sigma_k+1 - Sigma_k, 1e-10 I)
// where max clamps the eigenvalues of the symmetric difference, so every
// Sigma_u is positive definite. Submap origins are a subset of the robot
// poses; loop closures connect robot poses (Cauchy loss).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <optional>

#include "mapping/graph/rover_graph.h"

namespace rover::mapping {

class SequentialOdometryGraph {
 public:
  explicit SequentialOdometryGraph(const RoverGraphOptions& options = {});

  /// Prior on the first pose.
  void AddPrior(int64_t pose, const Eigen::Isometry3d& T_world_body, const Matrix6d& covariance);

  /// Filter estimate T_odom_body of pose `pose` in one fixed odometry frame,
  /// with its covariance over [dp (odom frame); dtheta (right)]. Poses must
  /// come in increasing order; each one is chained to the previous one.
  void AddOdometryPose(int64_t pose, const Eigen::Isometry3d& T_odom_body,
                       const Matrix6d& covariance);

  /// Loop closure T_a_b between two robot poses (robust).
  void AddLoopClosure(int64_t pose_a, int64_t pose_b, const Eigen::Isometry3d& T_a_b,
                      const Matrix6d& covariance);

  RoverGraphSummary Optimize() { return graph_.Optimize(); }
  Eigen::Isometry3d Pose(int64_t pose) const { return graph_.Estimate(GraphKey::Pose(0, pose)); }

  /// The differenced covariance of the thesis, eq. 4.9, as used here.
  static Matrix6d DifferencedCovariance(const Matrix6d& previous, const Matrix6d& current);

 private:
  RoverGraph graph_;
  struct Last {
    int64_t pose;
    Eigen::Isometry3d T_odom_body;
    Matrix6d covariance;
  };
  std::optional<Last> last_;
};

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_GRAPH_SEQUENTIAL_ODOMETRY_GRAPH_H_
