#ifndef ROVER_ESTIMATOR_EVAL_MCAP_TRAJECTORY_H_
#define ROVER_ESTIMATOR_EVAL_MCAP_TRAJECTORY_H_

// Reads the filter's estimate out of a rover flight log (MCAP, ROS 2 CDR).
//
// The filter publishes
//  * nav_msgs/msg/Odometry on /estimator/odometry: header.stamp = sample time,
//    header.frame_id = the current local frame ("local/rover1/3"),
//    pose.pose = T_local_body, pose.covariance = row-major 6x6 over
//    (x, y, z, rotation about X, Y, Z), read as [dp; dtheta] with the body-side
//    attitude error of trajectory.h; twist.linear = body velocity in the body frame;
//  * geometry_msgs/msg/TransformStamped on /estimator/frame_switch at every
//    frame-of-reference switch: header.frame_id = old frame,
//    child_frame_id = new frame, transform = T_old_new, header.stamp = switch time.
//
// The reader chains the switches so that the whole trajectory is expressed in
// the frame of the first odometry sample:
//   T_first_body = T_first_old * ... * T_old_new * T_new_body.
// Covariances are rotated into the first frame; the uncertainty of the switch
// transforms themselves is not added, so after a switch the position
// covariance describes the error relative to the new local frame only.
//
// geometry_msgs/msg/PoseWithCovarianceStamped is accepted on the pose topic as
// well (same pose and covariance conventions, no velocity).

#include <cstddef>
#include <string>
#include <vector>

#include "estimator/eval/trajectory.h"

namespace rover::eval {

struct McapTrajectoryOptions {
  /// Topic of the poses (nav_msgs/Odometry or geometry_msgs/PoseWithCovarianceStamped).
  std::string topic = "/estimator/odometry";
  /// Topic of the frame switches (geometry_msgs/TransformStamped); empty
  /// disables chaining (every frame id is then taken as the same frame).
  std::string frame_switch_topic = "/estimator/frame_switch";
};

/// One frame-of-reference switch as logged.
struct FrameSwitch {
  Time stamp;
  std::string old_frame_id;
  std::string new_frame_id;
  Eigen::Isometry3d T_old_new = Eigen::Isometry3d::Identity();
};

/// What ReadMcapTrajectory() found.
struct McapTrajectory {
  /// Poses T_first_body in the frame `frame_id`, sorted by stamp.
  Trajectory trajectory;
  /// The frame of the first pose sample, which the trajectory is expressed in.
  std::string frame_id;
  /// The switches on the switch topic, sorted by stamp.
  std::vector<FrameSwitch> switches;
  /// Pose messages dropped because a later message had the same stamp.
  std::size_t duplicate_stamps = 0;
  /// Damage the MCAP reader reported (unreadable chunks); their messages are missing.
  std::vector<std::string> damage;
};

/// Reads the pose topic of the MCAP log at `path` and chains the frame
/// switches (see the header comment). Throws EvalError for a file that is not
/// MCAP, a missing topic (the message lists the topics present), a topic of
/// another message type, an undecodable message, a non-unit quaternion, a
/// pose in a frame not connected to the first one by switches, or no poses.
/// Message errors read "FILE: message N on TOPIC (log time T): expected ..., found ...".
McapTrajectory ReadMcapTrajectory(const std::string& path,
                                  const McapTrajectoryOptions& options = {});

}  // namespace rover::eval

#endif  // ROVER_ESTIMATOR_EVAL_MCAP_TRAJECTORY_H_
