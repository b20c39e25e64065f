#ifndef ROVER_HIL_SIM_MOTION_TRAJECTORY_SAMPLE_H_
#define ROVER_HIL_SIM_MOTION_TRAJECTORY_SAMPLE_H_

// Ground truth of the simulated body (= IMU) frame at one instant, and the
// interface every motion source implements. The world frame is gravity-aligned
// with z up; the body frame has x forward, y left, z up.

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace rover::sim {

/// Standard gravity; the simulated world has uniform gravity (0, 0, -g).
inline constexpr double kStandardGravity_m_s2 = 9.80665;

/// Gravity vector in the world frame.
inline Eigen::Vector3d GravityWorld_m_s2() { return {0.0, 0.0, -kStandardGravity_m_s2}; }

/// Exact state of the body frame at time t_s (seconds since the start of the
/// motion). Every rate is an analytic derivative of the pose, never a finite
/// difference, so an ideal IMU built from it integrates back to the pose.
struct TrajectorySample {
  double t_s = 0.0;
  Eigen::Vector3d p_world_body = Eigen::Vector3d::Zero();  ///< metres
  Eigen::Vector3d v_world_m_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d a_world_m_s2 = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q_world_body = Eigen::Quaterniond::Identity();
  Eigen::Vector3d omega_body_rad_s = Eigen::Vector3d::Zero();   ///< angular rate, body axes
  Eigen::Vector3d alpha_body_rad_s2 = Eigen::Vector3d::Zero();  ///< d/dt omega_body
  /// What an ideal accelerometer measures: R_world_body^T (a - g).
  Eigen::Vector3d specific_force_body_m_s2 = Eigen::Vector3d::Zero();
};

/// Anything that yields ground truth as a function of time: the terrain-driven
/// rover trajectory, the closed-form circuit, a replayed log.
class MotionSource {
 public:
  virtual ~MotionSource() = default;
  /// State at t_s seconds after the start; sources clamp outside their span.
  virtual TrajectorySample Evaluate(double t_s) const = 0;
};

/// The sample's pose as a transform T_world_body.
inline Eigen::Isometry3d PoseOf(const TrajectorySample& sample) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = sample.q_world_body.toRotationMatrix();
  T.translation() = sample.p_world_body;
  return T;
}

}  // namespace rover::sim

#endif  // ROVER_HIL_SIM_MOTION_TRAJECTORY_SAMPLE_H_
