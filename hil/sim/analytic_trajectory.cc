#include "hil/sim/analytic_trajectory.h"

#include <cmath>

#include "hil/sim/motion/euler_rates.h"

namespace rover::sim {

TrajectorySample AnalyticTrajectory::Evaluate(double t_s) const {
  const auto& o = options_;
  const double w = o.speed_m_s / o.radius_m;  // turn rate of the circuit
  const double wa = 2.0 * M_PI * o.attitude_frequency_hz;
  const double c = std::cos(w * t_s), s = std::sin(w * t_s);
  const double ca = std::cos(wa * t_s), sa = std::sin(wa * t_s);

  TrajectorySample out;
  out.t_s = t_s;
  out.p_world_body = {o.radius_m * s, o.radius_m * (1.0 - c), o.heave_amplitude_m * sa};
  out.v_world_m_s = {o.radius_m * w * c, o.radius_m * w * s, o.heave_amplitude_m * wa * ca};
  out.a_world_m_s2 = {-o.radius_m * w * w * s, o.radius_m * w * w * c,
                      -o.heave_amplitude_m * wa * wa * sa};

  // Z-Y-X Euler angles and their rates; the heading follows the circuit.
  const double yaw = w * t_s, yaw_rate = w;
  const double pitch = o.pitch_amplitude_rad * sa, pitch_rate = o.pitch_amplitude_rad * wa * ca;
  const double roll = o.roll_amplitude_rad * ca, roll_rate = -o.roll_amplitude_rad * wa * sa;
  const Eigen::Matrix3d R_world_body = (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                                        Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                                        Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
                                           .toRotationMatrix();
  out.q_world_body = Eigen::Quaterniond(R_world_body);
  EulerZyxJet euler;
  euler.roll = roll;
  euler.pitch = pitch;
  euler.yaw = yaw;
  euler.roll_rate = roll_rate;
  euler.pitch_rate = pitch_rate;
  euler.yaw_rate = yaw_rate;
  euler.roll_accel = -o.roll_amplitude_rad * wa * wa * ca;
  euler.pitch_accel = -o.pitch_amplitude_rad * wa * wa * sa;
  out.omega_body_rad_s = BodyRates_rad_s(euler);
  out.alpha_body_rad_s2 = BodyAngularAcceleration_rad_s2(euler);
  out.specific_force_body_m_s2 =
      R_world_body.transpose() * (out.a_world_m_s2 - GravityWorld_m_s2());
  return out;
}

}  // namespace rover::sim
