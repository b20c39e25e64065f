#include "hil/sim/analytic_trajectory.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

namespace rover::sim {
namespace {

// Rates and specific force must be the exact derivatives of the pose; check
// them against central differences of the trajectory itself.
TEST(AnalyticTrajectoryTest, RatesMatchNumericDerivatives) {
  const AnalyticTrajectory trajectory(AnalyticTrajectoryOptions{});
  const double h = 1e-4;
  for (double t : {0.0, 1.3, 7.9, 42.0, 133.7}) {
    const TrajectorySample now = trajectory.Evaluate(t);
    const TrajectorySample before = trajectory.Evaluate(t - h);
    const TrajectorySample after = trajectory.Evaluate(t + h);
    const Eigen::Vector3d v_numeric = (after.p_world_body - before.p_world_body) / (2 * h);
    EXPECT_LT((v_numeric - now.v_world_m_s).norm(), 1e-7) << "t=" << t;

    const Eigen::Quaterniond dq = before.q_world_body.conjugate() * after.q_world_body;
    const Eigen::AngleAxisd aa(dq);
    const Eigen::Vector3d omega_numeric = aa.angle() * aa.axis() / (2 * h);
    EXPECT_LT((omega_numeric - now.omega_body_rad_s).norm(), 1e-7) << "t=" << t;

    const Eigen::Vector3d a_numeric = (after.v_world_m_s - before.v_world_m_s) / (2 * h);
    const Eigen::Vector3d f_numeric =
        now.q_world_body.conjugate() * (a_numeric + Eigen::Vector3d(0, 0, 9.80665));
    EXPECT_LT((f_numeric - now.specific_force_body_m_s2).norm(), 1e-6) << "t=" << t;
    EXPECT_LT((a_numeric - now.a_world_m_s2).norm(), 1e-6) << "t=" << t;

    const Eigen::Vector3d alpha_numeric =
        (after.omega_body_rad_s - before.omega_body_rad_s) / (2 * h);
    EXPECT_LT((alpha_numeric - now.alpha_body_rad_s2).norm(), 1e-6) << "t=" << t;
  }
}

TEST(AnalyticTrajectoryTest, DrivesAtConfiguredSpeed) {
  AnalyticTrajectoryOptions options;
  options.heave_amplitude_m = 0.0;
  const AnalyticTrajectory trajectory(options);
  EXPECT_NEAR(trajectory.Evaluate(3.0).v_world_m_s.norm(), options.speed_m_s, 1e-12);
}

}  // namespace
}  // namespace rover::sim
