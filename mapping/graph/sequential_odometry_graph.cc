#include "mapping/graph/sequential_odometry_graph.h"

#include <Eigen/Eigenvalues>

namespace rover::mapping {

SequentialOdometryGraph::SequentialOdometryGraph(const RoverGraphOptions& options)
    : graph_([&] {
        RoverGraphOptions o = options;
        o.compute_origin_covariances = false;
        return o;
      }()) {}

Matrix6d SequentialOdometryGraph::DifferencedCovariance(const Matrix6d& previous,
                                                        const Matrix6d& current) {
  const Matrix6d D = 0.5 * ((current - previous) + (current - previous).transpose());
  const Eigen::SelfAdjointEigenSolver<Matrix6d> eig(D);
  const Eigen::Matrix<double, 6, 1> lambda = eig.eigenvalues().cwiseMax(1e-10);
  return eig.eigenvectors() * lambda.asDiagonal() * eig.eigenvectors().transpose();
}

void SequentialOdometryGraph::AddPrior(int64_t pose, const Eigen::Isometry3d& T_world_body,
                                       const Matrix6d& covariance) {
  graph_.AddPrior(GraphKey::Pose(0, pose), T_world_body, covariance);
}

void SequentialOdometryGraph::AddOdometryPose(int64_t pose, const Eigen::Isometry3d& T_odom_body,
                                              const Matrix6d& covariance) {
  if (last_) {
    if (pose <= last_->pose) throw GraphError("odometry poses must come in increasing order");
    const Eigen::Isometry3d u = last_->T_odom_body.inverse() * T_odom_body;
    // The difference is over [dp (odom); dtheta]; u's translation error is in
    // the previous body frame.
    Matrix6d G = Matrix6d::Identity();
    G.topLeftCorner<3, 3>() = last_->T_odom_body.linear().transpose();
    const Matrix6d C = G * DifferencedCovariance(last_->covariance, covariance) * G.transpose();
    graph_.AddBetween(GraphKey::Pose(0, last_->pose), GraphKey::Pose(0, pose), u, C, false);
  }
  last_ = Last{pose, T_odom_body, covariance};
}

void SequentialOdometryGraph::AddLoopClosure(int64_t pose_a, int64_t pose_b,
                                             const Eigen::Isometry3d& T_a_b,
                                             const Matrix6d& covariance) {
  graph_.AddBetween(GraphKey::Pose(0, pose_a), GraphKey::Pose(0, pose_b), T_a_b, covariance, true);
}

}  // namespace rover::mapping
