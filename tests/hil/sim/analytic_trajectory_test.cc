#include "hil/sim/analytic_trajectory.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "hil/sim/imu_error_model.h"

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
    const Eigen::Vector3d v_numeric = (after.p_local_body - before.p_local_body) / (2 * h);
    EXPECT_LT((v_numeric - now.v_local_body_m_s).norm(), 1e-7) << "t=" << t;

    const Eigen::Quaterniond dq = before.q_local_body.conjugate() * after.q_local_body;
    const Eigen::AngleAxisd aa(dq);
    const Eigen::Vector3d omega_numeric = aa.angle() * aa.axis() / (2 * h);
    EXPECT_LT((omega_numeric - now.omega_body_rad_s).norm(), 1e-7) << "t=" << t;

    const Eigen::Vector3d a_numeric = (after.v_local_body_m_s - before.v_local_body_m_s) / (2 * h);
    const Eigen::Vector3d f_numeric =
        now.q_local_body.conjugate() * (a_numeric + Eigen::Vector3d(0, 0, 9.80665));
    EXPECT_LT((f_numeric - now.specific_force_body_m_s2).norm(), 1e-6) << "t=" << t;
  }
}

TEST(AnalyticTrajectoryTest, DrivesAtConfiguredSpeed) {
  AnalyticTrajectoryOptions options;
  options.heave_amplitude_m = 0.0;
  const AnalyticTrajectory trajectory(options);
  EXPECT_NEAR(trajectory.Evaluate(3.0).v_local_body_m_s.norm(), options.speed_m_s, 1e-12);
}

TEST(ImuErrorModelTest, SameSeedSameStream) {
  ImuErrorModel a(ImuErrorOptions{}), b(ImuErrorOptions{});
  ImuErrorOptions other;
  other.seed = 2;
  ImuErrorModel c(other);
  const Eigen::Vector3d w(0.1, 0.2, 0.3), f(0, 0, 9.8);
  bool differs = false;
  for (int i = 0; i < 100; ++i) {
    const ImuMeasurement ma = a.Apply(w, f, 0.0025), mb = b.Apply(w, f, 0.0025);
    const ImuMeasurement mc = c.Apply(w, f, 0.0025);
    ASSERT_EQ(ma.angular_velocity_rad_s, mb.angular_velocity_rad_s);
    ASSERT_EQ(ma.linear_acceleration_m_s2, mb.linear_acceleration_m_s2);
    differs |= ma.angular_velocity_rad_s != mc.angular_velocity_rad_s;
  }
  EXPECT_TRUE(differs);
}

// The discrete white noise must have sigma = density / sqrt(dt).
TEST(ImuErrorModelTest, WhiteNoiseMatchesDensity) {
  ImuErrorOptions options;
  options.gyro_bias_random_walk_rad_s2_sqrt_hz = 0.0;
  options.accel_bias_random_walk_m_s3_sqrt_hz = 0.0;
  ImuErrorModel model(options);
  const double dt = 1.0 / 400.0;
  const int n = 200000;
  double sum = 0.0, sum_sq = 0.0;
  for (int i = 0; i < n; ++i) {
    const double x = model.Apply(Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), dt)
                         .angular_velocity_rad_s.x() -
                     model.gyro_bias_rad_s().x();
    sum += x;
    sum_sq += x * x;
  }
  const double mean = sum / n;
  const double sigma = std::sqrt(sum_sq / n - mean * mean);
  const double expected = options.gyro_noise_density_rad_s_sqrt_hz / std::sqrt(dt);
  EXPECT_NEAR(sigma / expected, 1.0, 0.01);
  EXPECT_NEAR(mean, 0.0, 4.0 * expected / std::sqrt(n));
}

}  // namespace
}  // namespace rover::sim
