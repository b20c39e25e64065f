// Every analytic Jacobian of the filter against central differences of the
// nonlinear function it linearises: the propagation step, the process noise
// (against the exact Van Loan integral), the relative-pose and wheel
// measurement models, and the frame switch.

#include <gtest/gtest.h>

#include <unsupported/Eigen/MatrixFunctions>

#include "core/geometry/so3.h"
#include "core/geometry/yaw.h"
#include "estimator/eskf/frame_switcher.h"
#include "estimator/eskf/propagator/imu_propagator.h"
#include "estimator/eskf/update/relative_pose_updater.h"
#include "estimator/eskf/update/wheel_odometry_updater.h"
#include "tests/estimator/eskf/eskf_test_util.h"

namespace rover::estimator {
namespace {

using test::ErrorBetween;
using test::Perturbed;
using test::RandomState;
using test::RandomVector;

constexpr double kEps = 1e-6;

ImuMeasurement Reading(Time t, const Eigen::Vector3d& w, const Eigen::Vector3d& f) {
  ImuMeasurement m;
  m.stamp = t;
  m.angular_velocity_rad_s = w;
  m.linear_acceleration_m_s2 = f;
  return m;
}

TEST(ImuPropagatorTest, TransitionIsTheJacobianOfTheStep) {
  std::mt19937_64 rng(11);
  const ImuPropagator propagator{ImuNoiseOptions{}};
  for (int trial = 0; trial < 5; ++trial) {
    FilterState s = RandomState(rng, 0);
    // A long, fast step makes every term matter.
    const ImuMeasurement m0 = Reading(s.core.stamp, RandomVector(rng, 0.8),
                                      Eigen::Vector3d(0.3, -0.2, 9.8) + RandomVector(rng, 0.5));
    const ImuMeasurement m1 =
        Reading(s.core.stamp + Duration::Milliseconds(50), RandomVector(rng, 0.8),
                Eigen::Vector3d(-0.1, 0.4, 9.7) + RandomVector(rng, 0.5));
    const PropagationStep step = propagator.Integrate(s.core, m0, m1);
    Matrix15d phi = Matrix15d::Identity();
    step.phi.ApplyLeft(phi);

    FilterState next = s;
    next.core = step.next;
    for (int k = 0; k < 15; ++k) {
      Eigen::VectorXd e = Eigen::VectorXd::Zero(15);
      e(k) = kEps;
      FilterState plus = s, minus = s;
      plus.core = propagator.Integrate(Perturbed(s, e).core, m0, m1).next;
      minus.core = propagator.Integrate(Perturbed(s, -e).core, m0, m1).next;
      const Eigen::VectorXd column =
          (ErrorBetween(next, plus) - ErrorBetween(next, minus)) / (2.0 * kEps);
      EXPECT_LT((column - phi.col(k)).norm(), 1e-7)
          << "column " << k << "\nnumeric " << column.transpose() << "\nanalytic "
          << phi.col(k).transpose();
    }
  }
}

TEST(ImuPropagatorTest, BackwardStepInvertsForwardStep) {
  std::mt19937_64 rng(12);
  const ImuPropagator propagator{ImuNoiseOptions{}};
  FilterState s = RandomState(rng, 0);
  const ImuMeasurement m =
      Reading(s.core.stamp, RandomVector(rng, 0.5), Eigen::Vector3d(0.1, 0.2, 9.8));
  ImuMeasurement later = m;
  later.stamp = m.stamp + Duration::Milliseconds(10);
  const NominalState forward = propagator.Integrate(s.core, m, later).next;
  const NominalState back = propagator.Integrate(forward, later, m).next;
  EXPECT_LT((back.p_local_body - s.core.p_local_body).norm(), 1e-12);
  EXPECT_LT((back.v_local_m_s - s.core.v_local_m_s).norm(), 1e-12);
  EXPECT_LT(LogSO3(back.R_local_body.transpose() * s.core.R_local_body).norm(), 1e-12);
}

// Exact discrete noise of the linear model dx = F x + G n with constant F:
// Van Loan: expm([-F, GQG^T; 0, F^T] dt) = [., Phi^-1 Qd; 0, Phi^T].
Matrix15d VanLoan(const Eigen::Matrix3d& R, const Eigen::Vector3d& f, const Eigen::Vector3d& w,
                  double dt, const ImuNoiseOptions& o) {
  Matrix15d F = Matrix15d::Zero();
  F.block<3, 3>(kDp, kDv).setIdentity();
  F.block<3, 3>(kDv, kDtheta) = -R * skew(f);
  F.block<3, 3>(kDv, kDba) = -R;
  F.block<3, 3>(kDtheta, kDtheta) = -skew(w);
  F.block<3, 3>(kDtheta, kDbg) = -Eigen::Matrix3d::Identity();
  Matrix15d GQG = Matrix15d::Zero();
  const auto sq = [](double x) { return x * x; };
  GQG.block<3, 3>(kDv, kDv).diagonal().setConstant(sq(o.accel_noise_density_m_s2_sqrt_hz));
  GQG.block<3, 3>(kDtheta, kDtheta).diagonal().setConstant(sq(o.gyro_noise_density_rad_s_sqrt_hz));
  GQG.block<3, 3>(kDba, kDba).diagonal().setConstant(sq(o.accel_bias_random_walk_m_s3_sqrt_hz));
  GQG.block<3, 3>(kDbg, kDbg).diagonal().setConstant(sq(o.gyro_bias_random_walk_rad_s2_sqrt_hz));
  Eigen::Matrix<double, 30, 30> M = Eigen::Matrix<double, 30, 30>::Zero();
  M.topLeftCorner<15, 15>() = -F * dt;
  M.topRightCorner<15, 15>() = GQG * dt;
  M.bottomRightCorner<15, 15>() = F.transpose() * dt;
  const Eigen::Matrix<double, 30, 30> E = M.exp();
  const Matrix15d phi = E.bottomRightCorner<15, 15>().transpose();
  return phi * E.topRightCorner<15, 15>();
}

TEST(ImuPropagatorTest, ProcessNoiseMatchesVanLoanIntegral) {
  ImuNoiseOptions o;
  // Large bias walks so the dt^2 and dt^3 terms are visible above rounding.
  o.accel_bias_random_walk_m_s3_sqrt_hz = 5e-3;
  o.gyro_bias_random_walk_rad_s2_sqrt_hz = 1e-3;
  const ImuPropagator propagator(o);
  std::mt19937_64 rng(13);
  const Eigen::Matrix3d R = test::RandomAttitude(rng, 0.3).toRotationMatrix();
  const Eigen::Vector3d f(0.4, -0.3, 9.8);
  for (double dt : {0.0025, 0.01}) {
    const Matrix15d exact = VanLoan(R, f, Eigen::Vector3d::Zero(), dt, o);
    const Matrix15d series = propagator.ProcessNoise(dt, R, f);
    // Block by block, relative to the block's size: the truncation error is
    // of order dt |F| relative to the lowest retained term.
    for (int r = 0; r < 15; r += 3) {
      for (int c = 0; c < 15; c += 3) {
        const double scale = exact.block<3, 3>(r, c).norm();
        if (scale == 0.0) {
          EXPECT_EQ((series.block<3, 3>(r, c).norm()), 0.0);
          continue;
        }
        EXPECT_LT((series.block<3, 3>(r, c) - exact.block<3, 3>(r, c)).norm() / scale, 20.0 * dt)
            << "block (" << r << ", " << c << ") dt " << dt;
      }
    }
    // The dominant blocks agree far better than that.
    const auto rel = [&](int r, int c) {
      return (series.block<3, 3>(r, c) - exact.block<3, 3>(r, c)).norm() /
             exact.block<3, 3>(r, c).norm();
    };
    EXPECT_LT(rel(kDv, kDv), 1e-3);
    EXPECT_LT(rel(kDp, kDp), 1e-3);
  }
}

TEST(RelativePoseUpdaterTest, JacobianMatchesNumeric) {
  std::mt19937_64 rng(21);
  const RelativePoseUpdater updater{RelativePoseOptions{}};
  for (int trial = 0; trial < 5; ++trial) {
    FilterState s = RandomState(rng, 3);
    RelativePoseMeasurement z;
    const PoseClone& a = s.clones[0];
    const PoseClone& b = s.clones[2];
    // Near the prediction, but not at it, so r0 != 0 exercises Jl^-1(r0).
    z.p_from_to =
        a.R_local_body.transpose() * (b.p_local_body - a.p_local_body) + RandomVector(rng, 0.05);
    z.q_from_to = Eigen::Quaterniond(a.R_local_body.transpose() * b.R_local_body *
                                     ExpSO3(RandomVector(rng, 0.05)));
    const auto lin = updater.Linearise(s, z, 0, 2);
    for (int blk = 0; blk < 4; ++blk) {
      for (int k = 0; k < 3; ++k) {
        Eigen::VectorXd e = Eigen::VectorXd::Zero(s.Dim());
        e(lin.block_offsets[static_cast<size_t>(blk)] + k) = kEps;
        const auto plus = updater.Linearise(Perturbed(s, e), z, 0, 2);
        const auto minus = updater.Linearise(Perturbed(s, -e), z, 0, 2);
        // r(x (+) e) ~ r0 - H e.
        const Eigen::Matrix<double, 6, 1> column = -(plus.residual - minus.residual) / (2 * kEps);
        EXPECT_LT((column - lin.H.col(3 * blk + k)).norm(), 1e-7)
            << "block " << blk << " axis " << k << "\nnumeric " << column.transpose()
            << "\nanalytic " << lin.H.col(3 * blk + k).transpose();
      }
    }
  }
}

TEST(WheelOdometryUpdaterTest, JacobianMatchesNumeric) {
  std::mt19937_64 rng(22);
  WheelOdometryOptions o;
  o.use_yaw_rate = true;
  const WheelOdometryUpdater updater(o);
  const Eigen::Vector3d gyro(0.05, -0.02, 0.3);
  WheelVelocity z;
  z.forward_m_s = 0.3;
  z.yaw_rate_rad_s = 0.2;
  for (int trial = 0; trial < 5; ++trial) {
    FilterState s = RandomState(rng, 1);
    const auto lin = updater.Linearise(s, z, gyro);
    for (int blk = 0; blk < 3; ++blk) {
      for (int k = 0; k < 3; ++k) {
        Eigen::VectorXd e = Eigen::VectorXd::Zero(s.Dim());
        e(lin.block_offsets[static_cast<size_t>(blk)] + k) = kEps;
        const auto plus = updater.Linearise(Perturbed(s, e), z, gyro);
        const auto minus = updater.Linearise(Perturbed(s, -e), z, gyro);
        const Eigen::Vector3d column = -(plus.residual - minus.residual) / (2 * kEps);
        EXPECT_LT((column - lin.H.col(3 * blk + k)).norm(), 1e-8)
            << "block " << blk << " axis " << k;
      }
    }
  }
}

TEST(WheelOdometryUpdaterTest, WheelRatesToBodyVelocity) {
  WheelOdometryOptions o;
  o.wheel_radius_m = 0.1;
  o.track_m = 0.5;
  o.yaw_scrub_factor = 1.0;
  const WheelOdometryUpdater updater(o);
  // Left wheels 2 rad/s, right 4 rad/s: 0.3 m/s forward, 0.4 rad/s yaw.
  const WheelVelocity v = updater.FromWheelRates({2.0, 4.0, 2.0, 4.0});
  EXPECT_NEAR(v.forward_m_s, 0.3, 1e-12);
  EXPECT_NEAR(v.yaw_rate_rad_s, 0.4, 1e-12);
  EXPECT_NEAR(v.slip_m_s, 0.0, 1e-12);
  // Front-left spinning 1 rad/s faster than rear-left: 0.05 m/s of slip.
  EXPECT_NEAR(updater.FromWheelRates({3.0, 4.0, 2.0, 4.0}).slip_m_s, 0.05, 1e-12);
}

// The frame switch as a nonlinear map on states: the new frame is defined by
// the (perturbed) state's own position and yaw.
FilterState SwitchedCopy(const FilterState& s) {
  FilterState out = s;
  FrameSwitcher::Switch(out);
  return out;
}

TEST(FrameSwitcherTest, CovarianceTransformIsTheExactJacobian) {
  std::mt19937_64 rng(31);
  for (int trial = 0; trial < 4; ++trial) {
    const FilterState s = RandomState(rng, 3);
    const int dim = s.Dim();
    const FilterState switched = SwitchedCopy(s);
    Eigen::MatrixXd J(dim, dim);
    for (int k = 0; k < dim; ++k) {
      Eigen::VectorXd e = Eigen::VectorXd::Zero(dim);
      e(k) = kEps;
      J.col(k) = (ErrorBetween(switched, SwitchedCopy(Perturbed(s, e))) -
                  ErrorBetween(switched, SwitchedCopy(Perturbed(s, -e)))) /
                 (2 * kEps);
    }
    const Eigen::MatrixXd expected = J * s.P.topLeftCorner(dim, dim) * J.transpose();
    const Eigen::MatrixXd actual = switched.P.topLeftCorner(dim, dim);
    EXPECT_LT((actual - expected).norm() / expected.norm(), 1e-7);
  }
}

TEST(FrameSwitcherTest, ZeroesPositionAndYawKeepsTheRest) {
  std::mt19937_64 rng(32);
  FilterState s = RandomState(rng, 2);
  const FilterState before = s;
  const FrameSwitchRecord record = FrameSwitcher::Switch(s);
  EXPECT_EQ(record.old_frame_id, 0u);
  EXPECT_EQ(record.new_frame_id, 1u);
  EXPECT_EQ(s.frame_id, 1u);
  EXPECT_EQ(s.core.p_local_body, Eigen::Vector3d::Zero());
  EXPECT_NEAR(YawOf(s.core.R_local_body), 0.0, 1e-12);
  EXPECT_EQ(s.P.block(kDp, 0, 3, s.Dim()).norm(), 0.0);
  const Eigen::RowVector3d j = YawJacobianRight(s.core.R_local_body);
  const double yaw_var = j * s.P.block<3, 3>(kDtheta, kDtheta) * j.transpose();
  EXPECT_LT(yaw_var, 1e-14);
  // Roll/pitch: the tilt of the body z axis is frame-invariant, so its
  // variance survives; velocity speed and biases are untouched.
  EXPECT_NEAR(s.core.v_local_m_s.norm(), before.core.v_local_m_s.norm(), 1e-12);
  EXPECT_EQ(s.core.accel_bias_m_s2, before.core.accel_bias_m_s2);
  EXPECT_TRUE((s.P.block<6, 6>(kDba, kDba) == before.P.block<6, 6>(kDba, kDba)));
  // Relative poses between clones are frame-invariant.
  const auto relative = [](const FilterState& x) {
    return (x.clones[0].R_local_body.transpose() *
            (x.clones[1].p_local_body - x.clones[0].p_local_body))
        .eval();
  };
  EXPECT_LT((relative(s) - relative(before)).norm(), 1e-12);
  // The record: T_old_new and the covariance of [p; yaw] before the switch.
  EXPECT_EQ(record.p_old_new, before.core.p_local_body);
  EXPECT_NEAR(record.yaw_old_new_rad, YawOf(before.core.R_local_body), 1e-15);
  Eigen::Matrix<double, 4, Eigen::Dynamic> A = Eigen::MatrixXd::Zero(4, before.Dim());
  A.block<3, 3>(0, kDp).setIdentity();
  for (int k = 0; k < 3; ++k) {
    Eigen::VectorXd e = Eigen::VectorXd::Zero(before.Dim());
    e(kDtheta + k) = kEps;
    A(3, kDtheta + k) = (YawOf(Perturbed(before, e).core.R_local_body) -
                         YawOf(Perturbed(before, -e).core.R_local_body)) /
                        (2 * kEps);
  }
  const Eigen::Matrix4d expected =
      A * before.P.topLeftCorner(before.Dim(), before.Dim()) * A.transpose();
  EXPECT_LT((record.covariance - expected).norm() / expected.norm(), 1e-7);
}

}  // namespace
}  // namespace rover::estimator
