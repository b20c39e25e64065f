#ifndef ROVER_HIL_SIM_MOTION_EULER_RATES_H_
#define ROVER_HIL_SIM_MOTION_EULER_RATES_H_

// Body angular rate and acceleration of R = Rz(yaw) Ry(pitch) Rx(roll) from
// the Euler angles' time derivatives: exact kinematics, singular only at
// pitch = +-90 degrees, which a ground rover never reaches.

#include <Eigen/Core>
#include <cmath>

namespace rover::sim {

/// Z-Y-X Euler angles with their first and second time derivatives.
struct EulerZyxJet {
  double roll = 0.0, pitch = 0.0, yaw = 0.0;
  double roll_rate = 0.0, pitch_rate = 0.0, yaw_rate = 0.0;
  double roll_accel = 0.0, pitch_accel = 0.0, yaw_accel = 0.0;
};

/// omega_body = (roll' - yaw' sin p, pitch' cos r + yaw' cos p sin r,
///               -pitch' sin r + yaw' cos p cos r).
inline Eigen::Vector3d BodyRates_rad_s(const EulerZyxJet& e) {
  const double sr = std::sin(e.roll), cr = std::cos(e.roll);
  const double sp = std::sin(e.pitch), cp = std::cos(e.pitch);
  return {e.roll_rate - e.yaw_rate * sp, e.pitch_rate * cr + e.yaw_rate * cp * sr,
          -e.pitch_rate * sr + e.yaw_rate * cp * cr};
}

/// Time derivative of BodyRates_rad_s.
inline Eigen::Vector3d BodyAngularAcceleration_rad_s2(const EulerZyxJet& e) {
  const double sr = std::sin(e.roll), cr = std::cos(e.roll);
  const double sp = std::sin(e.pitch), cp = std::cos(e.pitch);
  const double dr = e.roll_rate, dp = e.pitch_rate, dy = e.yaw_rate;
  return {e.roll_accel - e.yaw_accel * sp - dy * dp * cp,
          e.pitch_accel * cr - dp * dr * sr + e.yaw_accel * cp * sr - dy * dp * sp * sr +
              dy * dr * cp * cr,
          -e.pitch_accel * sr - dp * dr * cr + e.yaw_accel * cp * cr - dy * dp * sp * cr -
              dy * dr * cp * sr};
}

}  // namespace rover::sim

#endif  // ROVER_HIL_SIM_MOTION_EULER_RATES_H_
