#ifndef ROVER_HIL_SIM_ANALYTIC_TRAJECTORY_H_
#define ROVER_HIL_SIM_ANALYTIC_TRAJECTORY_H_

// A smooth closed-form rover trajectory: a circuit at constant speed with
// terrain-like roll and pitch oscillations. Every derivative is analytic, so
// angular rate and specific force are exact, not finite differences. It is
// a reference motion for sensor-model tests (RoverTrajectory is the
// terrain-driven motion of the simulator).

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "hil/sim/motion/trajectory_sample.h"

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

class AnalyticTrajectory : public MotionSource {
 public:
  explicit AnalyticTrajectory(const AnalyticTrajectoryOptions& options) : options_(options) {}

  /// Exact state at `t` seconds after the start of the trajectory.
  TrajectorySample Evaluate(double t_s) const override;

 private:
  AnalyticTrajectoryOptions options_;
};

}  // namespace rover::sim

#endif  // ROVER_HIL_SIM_ANALYTIC_TRAJECTORY_H_
