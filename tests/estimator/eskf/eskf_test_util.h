#ifndef ROVER_TESTS_ESTIMATOR_ESKF_ESKF_TEST_UTIL_H_
#define ROVER_TESTS_ESTIMATOR_ESKF_ESKF_TEST_UTIL_H_

// Helpers shared by the filter tests: random states, the error between two
// states in the filter's convention, and exact IMU readings of an analytic
// motion (so propagation can be checked against truth).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <random>
#include <vector>

#include "core/geometry/so3.h"
#include "estimator/eskf/eskf_input.h"
#include "estimator/eskf/eskf_output.h"
#include "estimator/eskf/state/filter_state.h"

namespace rover::estimator::test {

inline Eigen::Vector3d RandomVector(std::mt19937_64& rng, double scale) {
  std::normal_distribution<double> n(0.0, scale);
  return {n(rng), n(rng), n(rng)};
}

inline Eigen::Quaterniond RandomAttitude(std::mt19937_64& rng, double tilt_scale_rad) {
  std::uniform_real_distribution<double> yaw(-3.0, 3.0);
  const Eigen::Vector3d tilt = RandomVector(rng, tilt_scale_rad);
  return Eigen::Quaterniond(Eigen::AngleAxisd(yaw(rng), Eigen::Vector3d::UnitZ())) *
         QuaternionFromRotationVector(Eigen::Vector3d(tilt.x(), tilt.y(), 0.0));
}

/// A state with random nominal values, `clones` random clones and a random
/// symmetric positive definite covariance.
inline FilterState RandomState(std::mt19937_64& rng, int clones) {
  FilterState s;
  s.core.stamp = Time::FromNanoseconds(5'000'000'000);
  s.core.p_local_body = RandomVector(rng, 3.0);
  s.core.v_local_m_s = RandomVector(rng, 0.5);
  s.core.SetAttitude(RandomAttitude(rng, 0.2));
  s.core.accel_bias_m_s2 = RandomVector(rng, 0.05);
  s.core.gyro_bias_rad_s = RandomVector(rng, 0.005);
  s.clone_count = clones;
  for (int i = 0; i < clones; ++i) {
    PoseClone& c = s.clones[static_cast<size_t>(i)];
    c.stamp = s.core.stamp - Duration::Milliseconds(100 * (clones - i));
    c.p_local_body = RandomVector(rng, 3.0);
    c.SetAttitude(RandomAttitude(rng, 0.2));
  }
  const int dim = s.Dim();
  Eigen::MatrixXd A(dim, dim);
  std::normal_distribution<double> n(0.0, 0.1);
  for (int r = 0; r < dim; ++r) {
    for (int c = 0; c < dim; ++c) A(r, c) = n(rng);
  }
  s.P.setZero();
  s.P.topLeftCorner(dim, dim) = A * A.transpose() + 0.01 * Eigen::MatrixXd::Identity(dim, dim);
  return s;
}

/// The error vector e with truth = est (+) e, in the filter's convention
/// (body-side attitude error; position, velocity and biases additive).
inline Eigen::VectorXd ErrorBetween(const FilterState& est, const FilterState& truth) {
  Eigen::VectorXd e(est.Dim());
  e.segment<3>(kDp) = truth.core.p_local_body - est.core.p_local_body;
  e.segment<3>(kDv) = truth.core.v_local_m_s - est.core.v_local_m_s;
  e.segment<3>(kDtheta) = LogSO3(est.core.R_local_body.transpose() * truth.core.R_local_body);
  e.segment<3>(kDba) = truth.core.accel_bias_m_s2 - est.core.accel_bias_m_s2;
  e.segment<3>(kDbg) = truth.core.gyro_bias_rad_s - est.core.gyro_bias_rad_s;
  for (int i = 0; i < est.clone_count; ++i) {
    const PoseClone& a = est.clones[static_cast<size_t>(i)];
    const PoseClone& b = truth.clones[static_cast<size_t>(i)];
    const int off = FilterState::CloneOffset(i);
    e.segment<3>(off) = b.p_local_body - a.p_local_body;
    e.segment<3>(off + 3) = LogSO3(a.R_local_body.transpose() * b.R_local_body);
  }
  return e;
}

/// `s` with the error vector e applied (truth = s (+) e).
inline FilterState Perturbed(const FilterState& s, const Eigen::VectorXd& e) {
  FilterState out = s;
  StateVector dx = StateVector::Zero();
  dx.head(s.Dim()) = e;
  out.ApplyCorrection(dx);
  return out;
}

/// Smooth analytic motion with exact IMU readings: position a sum of
/// sinusoids, attitude the exponential of a slowly varying rotation vector.
class AnalyticMotion {
 public:
  explicit AnalyticMotion(double gravity_m_s2 = 9.80665) : g_(0.0, 0.0, -gravity_m_s2) {}

  Eigen::Vector3d Position(double t) const {
    return {0.5 * std::sin(0.3 * t) + 0.2 * t, 0.4 * std::cos(0.2 * t), 0.05 * std::sin(0.5 * t)};
  }
  Eigen::Vector3d Velocity(double t) const {
    return {0.15 * std::cos(0.3 * t) + 0.2, -0.08 * std::sin(0.2 * t), 0.025 * std::cos(0.5 * t)};
  }
  Eigen::Vector3d Acceleration(double t) const {
    return {-0.045 * std::sin(0.3 * t), -0.016 * std::cos(0.2 * t), -0.0125 * std::sin(0.5 * t)};
  }
  // R(t) = Rz(yaw(t)) Ry(pitch(t)) Rx(roll(t)).
  Eigen::Matrix3d Attitude(double t) const {
    return (Eigen::AngleAxisd(Yaw(t), Eigen::Vector3d::UnitZ()) *
            Eigen::AngleAxisd(Pitch(t), Eigen::Vector3d::UnitY()) *
            Eigen::AngleAxisd(Roll(t), Eigen::Vector3d::UnitX()))
        .toRotationMatrix();
  }
  /// Body angular rate, from a central difference of the attitude (exact to
  /// ~1e-10 rad/s for this slow motion).
  Eigen::Vector3d BodyRate(double t) const {
    const double h = 1e-5;
    return LogSO3(Attitude(t - h).transpose() * Attitude(t + h)) / (2.0 * h);
  }
  ImuMeasurement Imu(double t, const Eigen::Vector3d& gyro_bias = Eigen::Vector3d::Zero(),
                     const Eigen::Vector3d& accel_bias = Eigen::Vector3d::Zero()) const {
    ImuMeasurement m;
    m.stamp = Time::FromNanoseconds(static_cast<int64_t>(std::llround(t * 1e9)));
    m.angular_velocity_rad_s = BodyRate(t) + gyro_bias;
    m.linear_acceleration_m_s2 = Attitude(t).transpose() * (Acceleration(t) - g_) + accel_bias;
    return m;
  }

 private:
  static double Yaw(double t) { return 0.3 * t + 0.2 * std::sin(0.4 * t); }
  static double Pitch(double t) { return 0.05 * std::sin(0.7 * t); }
  static double Roll(double t) { return 0.04 * std::cos(0.6 * t); }
  Eigen::Vector3d g_;
};

/// Records everything a filter emits.
class RecordingSink : public EskfOutputSink {
 public:
  void OnState(const EskfOutput& o) override { states.push_back(o); }
  void OnFrameSwitch(const FrameSwitchRecord& r) override { switches.push_back(r); }
  void OnPoseReport(const PoseReport& r) override { reports.push_back(r); }
  void OnReject(const RejectRecord& r) override { rejects.push_back(r); }
  std::vector<EskfOutput> states;
  std::vector<FrameSwitchRecord> switches;
  std::vector<PoseReport> reports;
  std::vector<RejectRecord> rejects;
};

}  // namespace rover::estimator::test

#endif  // ROVER_TESTS_ESTIMATOR_ESKF_ESKF_TEST_UTIL_H_
