#ifndef ROVER_HIL_SIM_ANALYTIC_TRAJECTORY_H_
#define ROVER_HIL_SIM_ANALYTIC_TRAJECTORY_H_

// A smooth closed-form rover trajectory: a circuit at constant speed with
// terrain-like roll and pitch oscillations. Every derivative is analytic, so
// angular rate and specific force are exact, not finite differences. It is
// the motion source of the early mission slice, until the terrain simulator
// drives poses from wheel contact.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "core/time/time.h"

namespace rover::sim {

/// Parameters of the circuit. Angles in radians, lengths in metres.
struct AnalyticTrajectoryOptions {
  double radius_m = 10.0;
  double speed_m_s = 0.3;
  double roll_amplitude_rad = 0.05;
  double pitch_amplitude_rad = 0.04;
  double attitude_frequency_hz = 0.2;
  double heave_amplitude_m = 0.05;
};

/// Ground truth at one instant, in the gravity-aligned local frame (z up).
struct TrajectorySample {
  Eigen::Vector3d p_local_body;
  Eigen::Vector3d v_local_body_m_s;
  Eigen::Quaterniond q_local_body;
  Eigen::Vector3d omega_body_rad_s;          ///< angular rate, body axes
  Eigen::Vector3d specific_force_body_m_s2;  ///< what an ideal accelerometer measures
};

class AnalyticTrajectory {
 public:
  explicit AnalyticTrajectory(const AnalyticTrajectoryOptions& options) : options_(options) {}

  /// Exact state at `t` seconds after the start of the trajectory.
  TrajectorySample Evaluate(double t_s) const;

 private:
  AnalyticTrajectoryOptions options_;
};

}  // namespace rover::sim

#endif  // ROVER_HIL_SIM_ANALYTIC_TRAJECTORY_H_
