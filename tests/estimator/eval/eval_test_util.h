#ifndef ROVER_TESTS_ESTIMATOR_EVAL_EVAL_TEST_UTIL_H_
#define ROVER_TESTS_ESTIMATOR_EVAL_EVAL_TEST_UTIL_H_

// Seeded random inputs shared by the trajectory-evaluation tests.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <random>

#include "core/geometry/se3.h"
#include "core/geometry/so3.h"
#include "estimator/eval/trajectory.h"

namespace rover::eval::testing {

inline Eigen::Vector3d RandomVector(std::mt19937_64& rng, double sigma) {
  std::normal_distribution<double> n(0.0, sigma);
  return {n(rng), n(rng), n(rng)};
}

inline Eigen::Quaterniond RandomRotation(std::mt19937_64& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  return Eigen::Quaterniond(n(rng), n(rng), n(rng), n(rng)).normalized();
}

inline Eigen::Isometry3d RandomPose(std::mt19937_64& rng, double translation_sigma) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = RandomRotation(rng).toRotationMatrix();
  T.translation() = RandomVector(rng, translation_sigma);
  return T;
}

/// A random symmetric positive-definite covariance over [dp; dtheta] with
/// standard deviations around `sigma_p` [m] and `sigma_theta` [rad] and
/// random correlations.
inline Matrix6d RandomCovariance(std::mt19937_64& rng, double sigma_p, double sigma_theta) {
  std::normal_distribution<double> n(0.0, 1.0);
  Matrix6d A;
  for (int r = 0; r < 6; ++r) {
    for (int c = 0; c < 6; ++c) A(r, c) = n(rng);
  }
  Matrix6d P = A * A.transpose() / 6.0 + 0.2 * Matrix6d::Identity();
  Vector6d scale;
  scale << sigma_p, sigma_p, sigma_p, sigma_theta, sigma_theta, sigma_theta;
  return scale.asDiagonal() * P * scale.asDiagonal();
}

/// A smooth random 3-D trajectory of `n` samples every `dt_ns`, starting at
/// `t0_ns`: a random walk in velocity and angular rate (speed ~ 1 m/s), so
/// that positions are not collinear and headings vary.
inline Trajectory RandomTrajectory(std::mt19937_64& rng, int n, int64_t dt_ns = 50'000'000,
                                   int64_t t0_ns = 1'000'000'000) {
  Trajectory t;
  Eigen::Vector3d p = RandomVector(rng, 1.0);
  Eigen::Quaterniond q = RandomRotation(rng);
  Eigen::Vector3d v(1.0, 0.0, 0.0);
  Eigen::Vector3d w = RandomVector(rng, 0.3);
  const double dt = static_cast<double>(dt_ns) * 1e-9;
  for (int i = 0; i < n; ++i) {
    PoseSample s;
    s.stamp = Time::FromNanoseconds(t0_ns + i * dt_ns);
    s.p_world_body = p;
    s.q_world_body = q;
    s.v_world_body_m_s = v;
    t.Append(s);
    p += v * dt;
    v += RandomVector(rng, 0.3) * dt;
    v.z() *= 0.9;
    q = (q * QuaternionFromRotationVector(w * dt)).normalized();
    w += RandomVector(rng, 0.5) * dt;
  }
  return t;
}

}  // namespace rover::eval::testing

#endif  // ROVER_TESTS_ESTIMATOR_EVAL_EVAL_TEST_UTIL_H_
