#ifndef ROVER_MAPPING_SLAM_GRAPH_FACTOR_RECORD_H_
#define ROVER_MAPPING_SLAM_GRAPH_FACTOR_RECORD_H_

// One factor of the rover graph as data: what mapd logs when it adds a
// factor, and what a restarted mapd or `rover-graph` reads back to rebuild
// the same graph. The covariance convention is RoverGraph's: [dp (m, frame
// a); dtheta (rad, right)]; a frame switch (w) keeps the filter's 4x4 over
// [dp; dyaw] in rows/columns 0, 1, 2, 5.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "core/log/msgs/rover_msgs.h"
#include "mapping/graph/graph_key.h"
#include "mapping/graph/pose_graph.h"
#include "mapping/graph/rover_graph.h"

namespace rover::mapping {

class RoverGraph;

enum class FactorKind : uint8_t {
  kPrior = log::rover_msgs::GraphFactor::kPrior,
  kFrameSwitch = log::rover_msgs::GraphFactor::kFrameSwitch,                  ///< w
  kFilterPose = log::rover_msgs::GraphFactor::kFilterPose,                    ///< v
  kSubmapMatch = log::rover_msgs::GraphFactor::kSubmapMatch,                  ///< c
  kRobotDetection = log::rover_msgs::GraphFactor::kRobotDetection,            ///< d
  kLandmarkObservation = log::rover_msgs::GraphFactor::kLandmarkObservation,  ///< o
};

/// "prior", "w", "v", "c", "d" or "o".
std::string_view ToString(FactorKind kind);

struct GraphFactorRecord {
  uint64_t id = 0;       ///< Per robot, from 1: the same factor read twice is one.
  int64_t stamp_ns = 0;  ///< When the measurement holds (switch, match, detection).
  FactorKind kind = FactorKind::kPrior;
  GraphKey a;
  std::optional<GraphKey> b;                                ///< Empty for a prior.
  Eigen::Isometry3d T_a_b = Eigen::Isometry3d::Identity();  ///< Prior: T_world_a.
  Matrix6d covariance = Matrix6d::Identity();
  bool robust = false;

  /// "w s0_3 -> s0_4" for messages.
  std::string Describe() const;
};

/// The prior that anchors robot `robot`'s first origin `submap` at
/// T_world_origin.
GraphFactorRecord OriginPriorFactor(int robot, int64_t submap,
                                    const Eigen::Isometry3d& T_world_origin,
                                    const Matrix6d& covariance);

/// The [x y z yaw] block of a 6x6 covariance over [x y z roll pitch yaw].
Eigen::Matrix4d FourDofBlock(const Matrix6d& covariance);

/// w: the filter's frame switch from local frame `old_frame` to
/// `old_frame + 1`, (p, yaw) with its 4x4 covariance over [dp; dyaw].
GraphFactorRecord FrameSwitchFactor(int robot, int64_t old_frame,
                                    const Eigen::Vector3d& p_old_new_m, double yaw_old_new_rad,
                                    const Eigen::Matrix4d& covariance);

/// c: a submap match T_a_b between two origins (robust).
GraphFactorRecord SubmapMatchFactor(const GraphKey& origin_a, const GraphKey& origin_b,
                                    const Eigen::Isometry3d& T_a_b, const Matrix6d& covariance);

/// v: the filter's estimate T_local_body of pose x^robot_pose in the local
/// frame of origin s^robot_submap, with its covariance (the graph's
/// convention, [dp (local); dtheta (right)]).
GraphFactorRecord FilterPoseFactor(int robot, int64_t submap, int64_t pose,
                                   const Eigen::Isometry3d& T_local_body,
                                   const Matrix6d& covariance);

/// o: robot pose x^robot_pose sees landmark l_landmark through a tag:
/// T_body_landmark = T_body_cam * T_cam_tag * T_landmark_tag^-1, with the
/// tag pose's covariance (over [dt (camera); dtheta (tag, right)])
/// propagated to first order (ComposeDetection). Robust.
GraphFactorRecord LandmarkObservationFactor(int robot, int64_t pose, int64_t landmark,
                                            const Eigen::Isometry3d& T_body_cam,
                                            const Eigen::Isometry3d& T_cam_tag,
                                            const Matrix6d& covariance_cam_tag,
                                            const Eigen::Isometry3d& T_landmark_tag);

/// d: robot `observer`'s pose x^observer_pose sees a marker of robot
/// `target`, whose pose at the same instant is x^target_target_pose:
/// T_body0_body1 = T_body_cam * T_cam_marker * T_body_marker^-1, with the
/// marker pose's covariance propagated to first order (ComposeDetection).
/// Robust.
GraphFactorRecord RobotDetectionFactor(int observer, int64_t observer_pose, int target,
                                       int64_t target_pose, const RobotDetection& detection);

/// Adds `record` to `graph` through the matching RoverGraph call. Throws
/// GraphError (naming the factor) for NaN, a covariance that is not
/// positive definite, or keys that do not fit the kind.
void AddToGraph(const GraphFactorRecord& record, RoverGraph* graph);

/// The log message of `record`; header.frame_id is `frame_id`. The rotation
/// travels as a quaternion, so FromMsg(ToMsg(r)) may differ from r in the
/// last bits: a graph that must be rebuilt exactly from its log adds
/// FromMsg(ToMsg(r)), as mapd does.
log::rover_msgs::GraphFactor ToMsg(const GraphFactorRecord& record, std::string_view frame_id);

/// The record of a logged factor. Throws GraphError naming the factor's id
/// and the field for an unknown kind, a malformed key or non-finite numbers.
GraphFactorRecord FromMsg(const log::rover_msgs::GraphFactor& msg);

/// Parses "s0_3", "x1_17", "l4"; nullopt for anything else.
std::optional<GraphKey> ParseGraphKey(std::string_view text);

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_SLAM_GRAPH_FACTOR_RECORD_H_
