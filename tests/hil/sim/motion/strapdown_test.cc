// Integrates noise-free IMU output of the terrain-driven trajectory back with
// a strap-down integrator and compares it with the ground truth: the rates
// and specific force must be the exact derivatives of the pose, or position
// and attitude drift.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/geometry/quaternion.h"
#include "hil/sim/motion/rover_trajectory.h"
#include "hil/sim/sensors/imu_model.h"
#include "tests/hil/sim/motion/test_terrain.h"

namespace rover::sim {
namespace {

struct NavState {
  Eigen::Quaterniond q;
  Eigen::Vector3d v;
  Eigen::Vector3d p;
};

struct NavDerivative {
  Eigen::Vector4d dq;  // (x, y, z, w)
  Eigen::Vector3d dv;
  Eigen::Vector3d dp;
};

NavDerivative Derivative(const NavState& s, const Eigen::Vector3d& omega,
                         const Eigen::Vector3d& f) {
  const Eigen::Quaterniond w(0.0, 0.5 * omega.x(), 0.5 * omega.y(), 0.5 * omega.z());
  return {(s.q * w).coeffs(), s.q * f + GravityWorld_m_s2(), s.v};
}

NavState Step(const NavState& s, const NavDerivative& d, double h) {
  NavState out;
  out.q.coeffs() = s.q.coeffs() + h * d.dq;
  out.v = s.v + h * d.dv;
  out.p = s.p + h * d.dp;
  return out;
}

// Classic RK4 on (q, v, p) with q renormalised after each step. The IMU only
// delivers samples at t_k, so the mid-interval rate and specific force come
// from cubic (4-point Lagrange) interpolation of the neighbouring samples.
NavState Rk4(const NavState& s, double h, const Eigen::Vector3d w[3], const Eigen::Vector3d f[3]) {
  const NavDerivative k1 = Derivative(s, w[0], f[0]);
  const NavDerivative k2 = Derivative(Step(s, k1, 0.5 * h), w[1], f[1]);
  const NavDerivative k3 = Derivative(Step(s, k2, 0.5 * h), w[1], f[1]);
  const NavDerivative k4 = Derivative(Step(s, k3, h), w[2], f[2]);
  NavState out;
  out.q.coeffs() = s.q.coeffs() + h / 6.0 * (k1.dq + 2.0 * k2.dq + 2.0 * k3.dq + k4.dq);
  out.q.normalize();
  out.v = s.v + h / 6.0 * (k1.dv + 2.0 * k2.dv + 2.0 * k3.dv + k4.dv);
  out.p = s.p + h / 6.0 * (k1.dp + 2.0 * k2.dp + 2.0 * k3.dp + k4.dp);
  return out;
}

template <typename T>
T Midpoint(const std::vector<T>& x, std::size_t k) {
  if (k == 0) return 0.375 * x[0] + 0.75 * x[1] - 0.125 * x[2];
  return (-x[k - 1] + 9.0 * x[k] + 9.0 * x[k + 1] - x[k + 2]) / 16.0;
}

TEST(StrapdownTest, NoiseFreeImuIntegratesBackToGroundTruth) {
  const Heightfield terrain = testing::MakeRoughTerrain();
  // Slopes of the test ground over a wheel-base (0.5 m) reach about 15
  // degrees; the cell noise on top is mm-scale roughness.
  double max_slope_rad = 0.0;
  const double b = 0.25;
  for (double x = -10; x < 10; x += 0.05) {
    for (double y = -10; y < 10; y += 0.05) {
      const Eigen::Vector2d g((terrain.HeightAt(x + b, y) - terrain.HeightAt(x - b, y)) / (2 * b),
                              (terrain.HeightAt(x, y + b) - terrain.HeightAt(x, y - b)) / (2 * b));
      max_slope_rad = std::max(max_slope_rad, std::atan(g.norm()));
    }
  }
  EXPECT_GT(max_slope_rad, 12.0 * M_PI / 180.0);
  EXPECT_LT(max_slope_rad, 18.0 * M_PI / 180.0);

  Route route;
  route.start_xy_m = {-2.5, -2.0};
  route.start_yaw_rad = 0.0;
  route.start_hold_s = 1.0;
  route
      .DriveTo({0.0, -1.75}, 0.4)     // gentle corner (-13 deg) here: rounded off while driving
      .DriveTo({2.0, -2.0}, 0.3)      // 97 deg: stop and turn on the spot
      .DriveTo({2.0, 0.5}, 0.3, 1.5)  // stop 1.5 s, then an 83 deg turn on the spot
      .DriveTo({-0.5, 0.8}, 0.5)      // 61 deg turn on the spot
      .Revisit(-1, 0.4);              // loop closure back to the start
  const RoverTrajectory trajectory(route, terrain);
  const double duration_s = 60.0;
  ASSERT_GT(trajectory.duration_s(), duration_s);
  int turns = 0, stops = 0;
  for (const PhaseInterval& p : trajectory.phases()) {
    if (p.end_s > duration_s) break;
    turns += p.phase == MotionPhase::kTurnInPlace;
    stops += p.phase == MotionPhase::kHold;
  }
  EXPECT_GE(turns, 3);
  EXPECT_GE(stops, 2);

  ImuModelOptions options;  // every error off: an ideal 400 Hz IMU
  options.rate_hz = 400.0;
  const Time start = Time::FromNanoseconds(1'000'000'000);
  ImuModel imu(options, start);
  const double dt = 1.0 / options.rate_hz;
  const auto steps = static_cast<std::size_t>(std::llround(duration_s / dt));
  std::vector<Eigen::Vector3d> omega, force;
  std::vector<TrajectorySample> truth;
  for (std::size_t k = 0; k < steps + 2; ++k) {
    TrajectorySample s;
    const drivers::ImuSample m = imu.Next(trajectory, &s);
    ASSERT_EQ(m.stamp, start + Duration::Nanoseconds(static_cast<int64_t>(k) * 2'500'000));
    omega.push_back(m.angular_velocity_rad_s);
    force.push_back(m.linear_acceleration_m_s2);
    truth.push_back(s);
  }

  NavState state{truth[0].q_world_body, truth[0].v_world_m_s, truth[0].p_world_body};
  double max_position_error_m = 0.0, max_attitude_error_rad = 0.0, max_tilt_rad = 0.0;
  for (std::size_t k = 0; k < steps; ++k) {
    const Eigen::Vector3d w[3] = {omega[k], Midpoint(omega, k), omega[k + 1]};
    const Eigen::Vector3d f[3] = {force[k], Midpoint(force, k), force[k + 1]};
    state = Rk4(state, dt, w, f);
    const TrajectorySample& t = truth[k + 1];
    max_tilt_rad =
        std::max(max_tilt_rad, std::acos(std::min(1.0, t.q_world_body.toRotationMatrix()(2, 2))));
    max_position_error_m = std::max(max_position_error_m, (state.p - t.p_world_body).norm());
    max_attitude_error_rad =
        std::max(max_attitude_error_rad, Boxminus(state.q, t.q_world_body).norm());
  }
  const TrajectorySample& end = truth[steps];
  const double final_position_error_m = (state.p - end.p_world_body).norm();
  const double final_attitude_error_rad = Boxminus(state.q, end.q_world_body).norm();
  const double deg = 180.0 / M_PI;
  RecordProperty("final_position_error_m", std::to_string(final_position_error_m));
  RecordProperty("max_attitude_error_deg", std::to_string(max_attitude_error_rad * deg));
  std::printf(
      "strap-down over %.0f s (route %.1f m, terrain slope up to %.1f deg, rover tilt "
      "up to %.1f deg): position error final %.2e m, max %.2e m; attitude error final "
      "%.2e deg, max %.2e deg\n",
      duration_s, trajectory.distance_m(), max_slope_rad * deg, max_tilt_rad * deg,
      final_position_error_m, max_position_error_m, final_attitude_error_rad * deg,
      max_attitude_error_rad * deg);
  EXPECT_GT(max_tilt_rad * deg, 5.0);
  EXPECT_LT(final_position_error_m, 0.01);
  EXPECT_LT(max_position_error_m, 0.01);
  EXPECT_LT(final_attitude_error_rad * deg, 0.05);
  EXPECT_LT(max_attitude_error_rad * deg, 0.05);
}

}  // namespace
}  // namespace rover::sim
