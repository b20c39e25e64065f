#include "hil/sim/analytic_trajectory.h"

#include <cmath>

namespace rover::sim {
namespace {
constexpr double kGravity_m_s2 = 9.80665;
}

TrajectorySample AnalyticTrajectory::Evaluate(double t_s) const {
  const auto& o = options_;
  const double w = o.speed_m_s / o.radius_m;  // turn rate of the circuit
  const double wa = 2.0 * M_PI * o.attitude_frequency_hz;
  const double c = std::cos(w * t_s), s = std::sin(w * t_s);
  const double ca = std::cos(wa * t_s), sa = std::sin(wa * t_s);

  TrajectorySample out;
  out.p_local_body = {o.radius_m * s, o.radius_m * (1.0 - c), o.heave_amplitude_m * sa};
  out.v_local_body_m_s = {o.radius_m * w * c, o.radius_m * w * s, o.heave_amplitude_m * wa * ca};
  const Eigen::Vector3d a_local_m_s2(-o.radius_m * w * w * s, o.radius_m * w * w * c,
                                     -o.heave_amplitude_m * wa * wa * sa);

  // Z-Y-X Euler angles and their rates; the heading follows the circuit.
  const double yaw = w * t_s, yaw_rate = w;
  const double pitch = o.pitch_amplitude_rad * sa, pitch_rate = o.pitch_amplitude_rad * wa * ca;
  const double roll = o.roll_amplitude_rad * ca, roll_rate = -o.roll_amplitude_rad * wa * sa;
  const Eigen::Matrix3d R_local_body = (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                                        Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                                        Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
                                           .toRotationMatrix();
  out.q_local_body = Eigen::Quaterniond(R_local_body);
  // Body rates from Z-Y-X Euler rates (exact kinematic relation).
  const double sr = std::sin(roll), cr = std::cos(roll);
  const double sp = std::sin(pitch), cp = std::cos(pitch);
  out.omega_body_rad_s = {roll_rate - yaw_rate * sp, pitch_rate * cr + yaw_rate * cp * sr,
                          -pitch_rate * sr + yaw_rate * cp * cr};
  const Eigen::Vector3d g_local_m_s2(0.0, 0.0, -kGravity_m_s2);
  out.specific_force_body_m_s2 = R_local_body.transpose() * (a_local_m_s2 - g_local_m_s2);
  return out;
}

}  // namespace rover::sim
