#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "core/geometry/quaternion.h"
#include "core/geometry/se3.h"
#include "core/geometry/so3.h"
#include "core/geometry/yaw.h"

namespace rover {
namespace {

constexpr double kPi = std::numbers::pi;

// Max-abs comparison that prints both matrices on failure; Eigen's isApprox
// is relative and therefore useless next to zero.
template <typename A, typename B>
::testing::AssertionResult MatrixNear(const A& actual, const B& expected, double tol) {
  if (actual.rows() != expected.rows() || actual.cols() != expected.cols()) {
    return ::testing::AssertionFailure() << "size mismatch";
  }
  const double err = (actual - expected).cwiseAbs().maxCoeff();
  if (err <= tol) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "max abs error " << err << " > " << tol << "\nactual:\n"
                                       << actual << "\nexpected:\n"
                                       << expected;
}

// Central-difference Jacobian at zero of f: R^N -> R^M. The step balances the
// O(h^2) truncation error against the O(eps / h) rounding error: both are
// ~1e-10 for the smooth, O(1)-scaled maps tested here.
template <int M, int N, typename F>
Eigen::Matrix<double, M, N> NumericJacobian(F f, double h = 1e-6) {
  Eigen::Matrix<double, M, N> J;
  for (int i = 0; i < N; ++i) {
    Eigen::Matrix<double, N, 1> d = Eigen::Matrix<double, N, 1>::Zero();
    d(i) = h;
    J.col(i) = (f(d) - f(-d)) / (2.0 * h);
  }
  return J;
}

constexpr double kJacobianTol = 1e-8;

// Seeded so that failures reproduce.
class GeometryTest : public ::testing::Test {
 protected:
  Eigen::Vector3d RandomUnitVector() {
    std::normal_distribution<double> normal(0.0, 1.0);
    const Eigen::Vector3d v(normal(rng_), normal(rng_), normal(rng_));
    return v.normalized();
  }

  Eigen::Vector3d RandomRotationVector(double angle_rad) { return angle_rad * RandomUnitVector(); }

  // Rotation vectors covering the regimes that need separate code paths: zero,
  // tiny (series), around the series threshold, generic, and close to pi.
  std::vector<Eigen::Vector3d> TestRotationVectors() {
    std::vector<Eigen::Vector3d> out;
    out.push_back(Eigen::Vector3d::Zero());
    for (const double angle : {1e-12, 1e-8, 1e-4, 0.0999, 0.1001, 0.5, 1.0, 2.0, 3.0, kPi - 1e-3}) {
      for (int i = 0; i < 3; ++i) out.push_back(RandomRotationVector(angle));
    }
    std::uniform_real_distribution<double> uniform_angle(0.0, kPi - 1e-3);
    for (int i = 0; i < 20; ++i) out.push_back(RandomRotationVector(uniform_angle(rng_)));
    return out;
  }

  Vector6d RandomTwist(double angle_rad) {
    std::normal_distribution<double> normal(0.0, 1.0);
    Vector6d xi;
    xi.head<3>() = Eigen::Vector3d(normal(rng_), normal(rng_), normal(rng_));
    xi.tail<3>() = RandomRotationVector(angle_rad);
    return xi;
  }

  Eigen::Isometry3d RandomPose() {
    std::uniform_real_distribution<double> uniform_angle(0.0, kPi);
    return ExpSE3(RandomTwist(uniform_angle(rng_)));
  }

  std::mt19937 rng_{20240611};
};

// ---------------------------------------------------------------- skew / vee

TEST_F(GeometryTest, SkewIsCrossProductAndVeeInvertsIt) {
  for (int i = 0; i < 10; ++i) {
    const Eigen::Vector3d v = 3.0 * RandomUnitVector();
    const Eigen::Vector3d w = RandomUnitVector();
    EXPECT_TRUE(MatrixNear(skew(v) * w, v.cross(w), 1e-15));
    EXPECT_TRUE(MatrixNear(skew(v).transpose(), -skew(v), 0.0));
    EXPECT_TRUE(MatrixNear(vee(skew(v)), v, 0.0));
  }
  Eigen::Matrix3d expected;
  expected << 0, -3, 2, 3, 0, -1, -2, 1, 0;
  EXPECT_TRUE(MatrixNear(skew(Eigen::Vector3d(1, 2, 3)), expected, 0.0));
}

// ------------------------------------------------------------------ SO(3) exp

TEST_F(GeometryTest, ExpSO3KnownValues) {
  EXPECT_TRUE(MatrixNear(ExpSO3(Eigen::Vector3d::Zero()), Eigen::Matrix3d::Identity(), 0.0));
  Eigen::Matrix3d Rz90;
  Rz90 << 0, -1, 0, 1, 0, 0, 0, 0, 1;
  EXPECT_TRUE(MatrixNear(ExpSO3(Eigen::Vector3d(0, 0, kPi / 2)), Rz90, 1e-15));
  EXPECT_TRUE(MatrixNear(ExpSO3(Eigen::Vector3d(kPi, 0, 0)),
                         Eigen::Vector3d(1, -1, -1).asDiagonal().toDenseMatrix(), 1e-15));
  // A full turn is the identity.
  EXPECT_TRUE(
      MatrixNear(ExpSO3(Eigen::Vector3d(0, 2 * kPi, 0)), Eigen::Matrix3d::Identity(), 1e-15));
  // Agrees with Eigen's AngleAxis.
  for (int i = 0; i < 10; ++i) {
    const Eigen::Vector3d axis = RandomUnitVector();
    const double angle = 0.7 * i;
    EXPECT_TRUE(
        MatrixNear(ExpSO3(angle * axis), Eigen::AngleAxisd(angle, axis).toRotationMatrix(), 2e-15));
  }
}

TEST_F(GeometryTest, ExpSO3IsAccurateForTinyAngles) {
  // For |phi| = 1e-8 the second-order expansion I + K + K^2/2 is exact to
  // ~1e-25, so any deviation above rounding is an error of the implementation.
  for (const double angle : {1e-8, 1e-10, 1e-14}) {
    const Eigen::Vector3d phi = RandomRotationVector(angle);
    const Eigen::Matrix3d K = skew(phi);
    const Eigen::Matrix3d expected = Eigen::Matrix3d::Identity() + K + 0.5 * K * K;
    EXPECT_TRUE(MatrixNear(ExpSO3(phi), expected, 2.3e-16)) << angle;
    // The off-diagonal entries carry phi itself and must be relatively exact.
    EXPECT_TRUE(MatrixNear(vee(ExpSO3(phi)), phi, 2.3e-16 * angle)) << angle;
  }
}

TEST_F(GeometryTest, ExpSO3IsOrthonormal) {
  for (const Eigen::Vector3d& phi : TestRotationVectors()) {
    const Eigen::Matrix3d R = ExpSO3(phi);
    EXPECT_TRUE(MatrixNear(R.transpose() * R, Eigen::Matrix3d::Identity(), 4e-15));
    EXPECT_NEAR(R.determinant(), 1.0, 1e-15);
  }
}

// ------------------------------------------------------------------ SO(3) log

TEST_F(GeometryTest, LogSO3InvertsExpSO3) {
  for (const Eigen::Vector3d& phi : TestRotationVectors()) {
    EXPECT_TRUE(MatrixNear(LogSO3(ExpSO3(phi)), phi, 2e-15 * std::max(1.0, phi.norm())))
        << phi.norm();
  }
}

TEST_F(GeometryTest, LogSO3IsRelativelyAccurateForTinyAngles) {
  for (const double angle : {1e-8, 1e-12, 1e-16}) {
    const Eigen::Vector3d phi = RandomRotationVector(angle);
    EXPECT_TRUE(MatrixNear(LogSO3(ExpSO3(phi)), phi, 1e-15 * angle)) << angle;
    EXPECT_TRUE(MatrixNear(LogSO3(QuaternionFromRotationVector(phi)), phi, 1e-15 * angle));
  }
}

TEST_F(GeometryTest, LogSO3NearPi) {
  for (const double gap : {1e-3, 1e-6, 1e-9, 1e-12}) {
    for (int i = 0; i < 5; ++i) {
      const Eigen::Vector3d phi = RandomRotationVector(kPi - gap);
      // The axis of a near half turn is determined by the symmetric part of R
      // and stays accurate; the tolerance is dominated by the rounding of R.
      EXPECT_TRUE(MatrixNear(LogSO3(ExpSO3(phi)), phi, 1e-13)) << gap;
      EXPECT_TRUE(MatrixNear(LogSO3(QuaternionFromRotationVector(phi)), phi, 1e-13)) << gap;
    }
  }
  // Exactly pi: +phi and -phi are both valid answers.
  const Eigen::Vector3d axis = RandomUnitVector();
  const Eigen::Vector3d log = LogSO3(ExpSO3(kPi * axis));
  EXPECT_NEAR(log.norm(), kPi, 1e-14);
  EXPECT_NEAR(std::abs(log.normalized().dot(axis)), 1.0, 1e-14);
  EXPECT_TRUE(MatrixNear(ExpSO3(log), ExpSO3(kPi * axis), 1e-14));
}

TEST_F(GeometryTest, LogSO3WrapsAnglesAbovePi) {
  const Eigen::Vector3d axis = RandomUnitVector();
  EXPECT_TRUE(MatrixNear(LogSO3(ExpSO3(1.5 * kPi * axis)), -0.5 * kPi * axis, 1e-14));
  EXPECT_TRUE(MatrixNear(LogSO3(ExpSO3(2.0 * kPi * axis)), Eigen::Vector3d::Zero(), 1e-14));
}

// ------------------------------------------------------------ SO(3) quaternion

TEST_F(GeometryTest, QuaternionExpMatchesMatrixExp) {
  for (const Eigen::Vector3d& phi : TestRotationVectors()) {
    const Eigen::Quaterniond q = QuaternionFromRotationVector(phi);
    EXPECT_NEAR(q.norm(), 1.0, 1e-15);
    EXPECT_GE(q.w(), 0.0);
    EXPECT_TRUE(MatrixNear(q.toRotationMatrix(), ExpSO3(phi), 2e-15));
  }
  const Eigen::Quaterniond q = QuaternionFromRotationVector(Eigen::Vector3d(0, 0, kPi / 2));
  EXPECT_NEAR(q.w(), std::sqrt(0.5), 2.3e-16);
  EXPECT_NEAR(q.z(), std::sqrt(0.5), 2.3e-16);
}

TEST_F(GeometryTest, QuaternionLogIsSignAndScaleInvariant) {
  for (const Eigen::Vector3d& phi : TestRotationVectors()) {
    const Eigen::Quaterniond q = QuaternionFromRotationVector(phi);
    const Eigen::Quaterniond minus_q(-q.coeffs());
    const Eigen::Quaterniond scaled_q(3.5 * q.coeffs());
    const double tol = 1e-15 * std::max(1.0, phi.norm());
    EXPECT_TRUE(MatrixNear(LogSO3(q), phi, tol));
    EXPECT_TRUE(MatrixNear(LogSO3(minus_q), phi, tol));
    EXPECT_TRUE(MatrixNear(LogSO3(scaled_q), phi, tol));
  }
}

// -------------------------------------------------------------- SO(3) Jacobians

TEST_F(GeometryTest, RightJacobianSO3MatchesNumeric) {
  for (const Eigen::Vector3d& phi : TestRotationVectors()) {
    const Eigen::Matrix3d R_inv = ExpSO3(phi).transpose();
    const auto f = [&](const Eigen::Vector3d& d) { return LogSO3(R_inv * ExpSO3(phi + d)); };
    EXPECT_TRUE(MatrixNear(RightJacobianSO3(phi), NumericJacobian<3, 3>(f), kJacobianTol))
        << phi.norm();
  }
}

TEST_F(GeometryTest, LeftJacobianSO3MatchesNumeric) {
  for (const Eigen::Vector3d& phi : TestRotationVectors()) {
    const Eigen::Matrix3d R_inv = ExpSO3(phi).transpose();
    const auto f = [&](const Eigen::Vector3d& d) { return LogSO3(ExpSO3(phi + d) * R_inv); };
    EXPECT_TRUE(MatrixNear(LeftJacobianSO3(phi), NumericJacobian<3, 3>(f), kJacobianTol))
        << phi.norm();
  }
}

TEST_F(GeometryTest, RightJacobianInverseSO3MatchesNumeric) {
  // The perturbation stays far below the 1e-3 gap to pi of the largest test
  // angle, so the logarithm never wraps inside the finite difference.
  for (const Eigen::Vector3d& phi : TestRotationVectors()) {
    const Eigen::Matrix3d R = ExpSO3(phi);
    const auto f = [&](const Eigen::Vector3d& d) { return Eigen::Vector3d(LogSO3(R * ExpSO3(d))); };
    EXPECT_TRUE(MatrixNear(RightJacobianInverseSO3(phi), NumericJacobian<3, 3>(f), kJacobianTol))
        << phi.norm();
  }
}

TEST_F(GeometryTest, LeftJacobianInverseSO3MatchesNumeric) {
  for (const Eigen::Vector3d& phi : TestRotationVectors()) {
    const Eigen::Matrix3d R = ExpSO3(phi);
    const auto f = [&](const Eigen::Vector3d& d) { return Eigen::Vector3d(LogSO3(ExpSO3(d) * R)); };
    EXPECT_TRUE(MatrixNear(LeftJacobianInverseSO3(phi), NumericJacobian<3, 3>(f), kJacobianTol))
        << phi.norm();
  }
}

TEST_F(GeometryTest, SO3JacobianIdentities) {
  std::vector<Eigen::Vector3d> phis = TestRotationVectors();
  // Beyond the range of LogSO3 the Jacobians are still defined up to 2 pi.
  phis.push_back(RandomRotationVector(kPi));
  phis.push_back(RandomRotationVector(4.0));
  phis.push_back(RandomRotationVector(6.0));
  for (const Eigen::Vector3d& phi : phis) {
    const Eigen::Matrix3d Jr = RightJacobianSO3(phi);
    const Eigen::Matrix3d Jl = LeftJacobianSO3(phi);
    const double tol = phi.norm() < 5.0 ? 1e-14 : 1e-12;  // Jr^-1 grows near 2 pi.
    EXPECT_TRUE(MatrixNear(RightJacobianInverseSO3(phi) * Jr, Eigen::Matrix3d::Identity(), tol))
        << phi.norm();
    EXPECT_TRUE(MatrixNear(Jr * RightJacobianInverseSO3(phi), Eigen::Matrix3d::Identity(), tol));
    EXPECT_TRUE(MatrixNear(LeftJacobianInverseSO3(phi) * Jl, Eigen::Matrix3d::Identity(), tol));
    EXPECT_TRUE(MatrixNear(Jr, LeftJacobianSO3(-phi), 1e-15));
    EXPECT_TRUE(MatrixNear(Jr, Jl.transpose(), 1e-15));
    // Jl = R Jr: both map the same tangent change, seen from either side.
    EXPECT_TRUE(MatrixNear(Jl, ExpSO3(phi) * Jr, 1e-14));
  }
  EXPECT_TRUE(
      MatrixNear(RightJacobianSO3(Eigen::Vector3d::Zero()), Eigen::Matrix3d::Identity(), 0));
  EXPECT_TRUE(
      MatrixNear(RightJacobianInverseSO3(Eigen::Vector3d::Zero()), Eigen::Matrix3d::Identity(), 0));
}

TEST_F(GeometryTest, SO3JacobianKnownValues) {
  // About z by a quarter turn, Jr's xy block is [[s, c-1], [1-c, s]] / t with
  // s = sin t, c = cos t, and 1 on the z axis.
  const double t = kPi / 2;
  Eigen::Matrix3d expected;
  expected << 1 / t, -1 / t, 0, 1 / t, 1 / t, 0, 0, 0, 1;
  EXPECT_TRUE(MatrixNear(LeftJacobianSO3(Eigen::Vector3d(0, 0, t)), expected, 1e-15));
  EXPECT_TRUE(MatrixNear(RightJacobianSO3(Eigen::Vector3d(0, 0, t)), expected.transpose(), 1e-15));
}

// ----------------------------------------------------------------------- SE(3)

TEST_F(GeometryTest, ExpSE3KnownValues) {
  Vector6d xi = Vector6d::Zero();
  xi.head<3>() << 1, 2, 3;
  Eigen::Isometry3d T = ExpSE3(xi);
  EXPECT_TRUE(MatrixNear(T.matrix(), Eigen::Isometry3d(Eigen::Translation3d(1, 2, 3)).matrix(), 0));

  // A quarter turn about z with rho = (pi/2, 0, 0) traces a quarter circle of
  // unit radius: the translation is (1, 1, 0).
  xi << kPi / 2, 0, 0, 0, 0, kPi / 2;
  T = ExpSE3(xi);
  EXPECT_TRUE(MatrixNear(T.translation(), Eigen::Vector3d(1, 1, 0), 1e-15));
  EXPECT_TRUE(MatrixNear(T.linear(), Rz(kPi / 2), 1e-15));
}

TEST_F(GeometryTest, LogSE3InvertsExpSE3) {
  for (const double angle : {0.0, 1e-12, 1e-8, 1e-4, 0.1, 1.0, 3.0, kPi - 1e-6}) {
    for (int i = 0; i < 5; ++i) {
      const Vector6d xi = RandomTwist(angle);
      EXPECT_TRUE(MatrixNear(LogSE3(ExpSE3(xi)), xi, 1e-12)) << angle;
    }
  }
  for (int i = 0; i < 10; ++i) {
    const Eigen::Isometry3d T = RandomPose();
    EXPECT_TRUE(MatrixNear(ExpSE3(LogSE3(T)).matrix(), T.matrix(), 1e-14));
  }
}

TEST_F(GeometryTest, AdjointMovesTwistsAcrossThePose) {
  for (int i = 0; i < 10; ++i) {
    const Eigen::Isometry3d T = RandomPose();
    const Vector6d xi = RandomTwist(0.8);
    const Matrix6d Ad = Adjoint(T);
    EXPECT_TRUE(
        MatrixNear((T * ExpSE3(xi) * T.inverse()).matrix(), ExpSE3(Ad * xi).matrix(), 1e-13));
    // Ad is the Jacobian of the conjugation.
    const auto f = [&](const Vector6d& d) { return LogSE3(T * ExpSE3(d) * T.inverse()); };
    EXPECT_TRUE(MatrixNear(Ad, NumericJacobian<6, 6>(f), kJacobianTol));
    // Homomorphism properties.
    const Eigen::Isometry3d T2 = RandomPose();
    EXPECT_TRUE(MatrixNear(Adjoint(T * T2), Ad * Adjoint(T2), 1e-13));
    EXPECT_TRUE(MatrixNear(Adjoint(T.inverse()), Ad.inverse(), 1e-12));
  }
}

TEST_F(GeometryTest, SE3JacobiansMatchNumeric) {
  for (const double angle : {0.0, 1e-8, 1e-4, 0.0999, 0.1001, 0.5, 2.0, kPi - 1e-3}) {
    for (int i = 0; i < 4; ++i) {
      const Vector6d xi = RandomTwist(angle);
      const Eigen::Isometry3d T = ExpSE3(xi);
      const Eigen::Isometry3d T_inv = T.inverse();
      const auto left = [&](const Vector6d& d) { return LogSE3(ExpSE3(xi + d) * T_inv); };
      const auto right = [&](const Vector6d& d) { return LogSE3(T_inv * ExpSE3(xi + d)); };
      const auto left_inv = [&](const Vector6d& d) { return Vector6d(LogSE3(ExpSE3(d) * T) - xi); };
      const auto right_inv = [&](const Vector6d& d) {
        return Vector6d(LogSE3(T * ExpSE3(d)) - xi);
      };
      EXPECT_TRUE(MatrixNear(LeftJacobianSE3(xi), NumericJacobian<6, 6>(left), kJacobianTol))
          << angle;
      EXPECT_TRUE(MatrixNear(RightJacobianSE3(xi), NumericJacobian<6, 6>(right), kJacobianTol))
          << angle;
      EXPECT_TRUE(
          MatrixNear(LeftJacobianInverseSE3(xi), NumericJacobian<6, 6>(left_inv), kJacobianTol))
          << angle;
      EXPECT_TRUE(
          MatrixNear(RightJacobianInverseSE3(xi), NumericJacobian<6, 6>(right_inv), kJacobianTol))
          << angle;
      EXPECT_TRUE(MatrixNear(LeftJacobianInverseSE3(xi) * LeftJacobianSE3(xi), Matrix6d::Identity(),
                             1e-13));
      EXPECT_TRUE(MatrixNear(RightJacobianInverseSE3(xi) * RightJacobianSE3(xi),
                             Matrix6d::Identity(), 1e-13));
      // Jl = Ad(Exp(xi)) Jr, as for SO(3).
      EXPECT_TRUE(MatrixNear(LeftJacobianSE3(xi), Adjoint(T) * RightJacobianSE3(xi), 1e-13));
    }
  }
}

// ----------------------------------------------------------------- quaternions

TEST_F(GeometryTest, NormalizePositiveW) {
  const Eigen::Quaterniond q = NormalizePositiveW(Eigen::Quaterniond(-2.0, 0.0, 0.0, 2.0));
  EXPECT_NEAR(q.w(), std::sqrt(0.5), 2.3e-16);
  EXPECT_NEAR(q.z(), -std::sqrt(0.5), 2.3e-16);
  EXPECT_NEAR(q.norm(), 1.0, 2.3e-16);
  const Eigen::Quaterniond p = NormalizePositiveW(Eigen::Quaterniond(0.5, 0.5, -0.5, 0.5));
  EXPECT_TRUE(MatrixNear(p.coeffs(), Eigen::Vector4d(0.5, -0.5, 0.5, 0.5), 2.3e-16));
}

TEST_F(GeometryTest, BoxplusIsRightPerturbation) {
  for (const Eigen::Vector3d& phi : TestRotationVectors()) {
    const Eigen::Quaterniond q = QuaternionFromRotationVector(RandomRotationVector(2.0));
    const Eigen::Quaterniond q_plus = Boxplus(q, phi);
    EXPECT_NEAR(q_plus.norm(), 1.0, 1e-15);
    EXPECT_TRUE(MatrixNear(q_plus.toRotationMatrix(), q.toRotationMatrix() * ExpSO3(phi), 1e-14));
  }
}

TEST_F(GeometryTest, BoxminusInvertsBoxplus) {
  for (const Eigen::Vector3d& d : TestRotationVectors()) {
    const Eigen::Quaterniond q = QuaternionFromRotationVector(RandomRotationVector(2.5));
    const double tol = 1e-15 * std::max(1.0, d.norm()) * 4.0;
    EXPECT_TRUE(MatrixNear(Boxminus(Boxplus(q, d), q), d, tol)) << d.norm();
    // The sign of the quaternions does not matter.
    EXPECT_TRUE(MatrixNear(Boxminus(Eigen::Quaterniond(-Boxplus(q, d).coeffs()), q), d, tol));
    const Eigen::Quaterniond q1 = QuaternionFromRotationVector(RandomRotationVector(1.0));
    const Eigen::Quaterniond back = Boxplus(q, Boxminus(q1, q));
    EXPECT_TRUE(MatrixNear(NormalizePositiveW(back).coeffs(), NormalizePositiveW(q1).coeffs(),
                           1e-15 * 4.0));
  }
}

TEST_F(GeometryTest, BoxminusJacobiansMatchNumeric) {
  for (const Eigen::Vector3d& r : TestRotationVectors()) {
    const Eigen::Quaterniond q_ref = QuaternionFromRotationVector(RandomRotationVector(1.7));
    const Eigen::Quaterniond q = Boxplus(q_ref, r);
    const Eigen::Vector3d r0 = Boxminus(q, q_ref);
    const auto wrt_q = [&](const Eigen::Vector3d& d) {
      return Eigen::Vector3d(Boxminus(Boxplus(q, d), q_ref));
    };
    const auto wrt_ref = [&](const Eigen::Vector3d& d) {
      return Eigen::Vector3d(Boxminus(q, Boxplus(q_ref, d)));
    };
    EXPECT_TRUE(MatrixNear(NumericJacobian<3, 3>(wrt_q), RightJacobianInverseSO3(r0), kJacobianTol))
        << r.norm();
    EXPECT_TRUE(
        MatrixNear(NumericJacobian<3, 3>(wrt_ref), -LeftJacobianInverseSO3(r0), kJacobianTol))
        << r.norm();
    // Boxplus(q, .) at 0 has the identity as tangent map.
    const auto plus = [&](const Eigen::Vector3d& d) {
      return Eigen::Vector3d(Boxminus(Boxplus(q, d), q));
    };
    EXPECT_TRUE(MatrixNear(NumericJacobian<3, 3>(plus), Eigen::Matrix3d::Identity(), kJacobianTol));
  }
}

// ------------------------------------------------------------------------ yaw

TEST_F(GeometryTest, RzAndYawOfKnownValues) {
  Eigen::Matrix3d expected;
  expected << 0, -1, 0, 1, 0, 0, 0, 0, 1;
  EXPECT_TRUE(MatrixNear(Rz(kPi / 2), expected, 2.3e-16));
  for (const double yaw : {-3.0, -1.0, 0.0, 0.3, 2.0, 3.1}) {
    EXPECT_NEAR(YawOf(Rz(yaw)), yaw, 1e-15);
    EXPECT_TRUE(MatrixNear(Rz(yaw), ExpSO3(Eigen::Vector3d(0, 0, yaw)), 1e-15));
  }
  // Z-Y-X Euler angles: the yaw is recovered regardless of pitch and roll.
  const Eigen::Matrix3d R = Rz(0.7) * Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitY()) *
                            Eigen::AngleAxisd(-1.2, Eigen::Vector3d::UnitX());
  EXPECT_NEAR(YawOf(R), 0.7, 1e-15);
}

TEST_F(GeometryTest, SplitYawRollPitchRecomposes) {
  for (const Eigen::Vector3d& phi : TestRotationVectors()) {
    const Eigen::Matrix3d R = ExpSO3(phi);
    const YawRollPitchSplit split = SplitYawRollPitch(R);
    EXPECT_TRUE(MatrixNear(split.R_yaw * split.R_rollpitch, R, 1e-15));
    EXPECT_TRUE(MatrixNear(split.R_yaw, Rz(split.yaw_rad), 0.0));
    EXPECT_NEAR(split.yaw_rad, YawOf(R), 0.0);
    EXPECT_NEAR(YawOf(split.R_rollpitch), 0.0, 1e-15);
    // The body x axis under R_rp has no y component and points forward.
    EXPECT_NEAR(split.R_rollpitch(1, 0), 0.0, 1e-15);
    EXPECT_GE(split.R_rollpitch(0, 0), 0.0);
    EXPECT_TRUE(MatrixNear(split.R_rollpitch.transpose() * split.R_rollpitch,
                           Eigen::Matrix3d::Identity(), 1e-15));
  }
  // Known Euler angles: R_rp = Ry(pitch) * Rx(roll).
  const Eigen::Matrix3d R_rp = Eigen::Matrix3d(Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitY())) *
                               Eigen::AngleAxisd(-1.2, Eigen::Vector3d::UnitX());
  const YawRollPitchSplit split = SplitYawRollPitch(Rz(-2.5) * R_rp);
  EXPECT_NEAR(split.yaw_rad, -2.5, 1e-15);
  EXPECT_TRUE(MatrixNear(split.R_rollpitch, R_rp, 1e-15));
}

TEST_F(GeometryTest, YawJacobianRightMatchesNumeric) {
  for (const Eigen::Vector3d& phi : TestRotationVectors()) {
    const Eigen::Matrix3d R = ExpSO3(phi);
    const double yaw0 = YawOf(R);
    // Differences are wrapped to (-pi, pi] so a heading near +-pi does not
    // produce a 2 pi jump inside the finite difference.
    const auto f = [&](const Eigen::Vector3d& d) {
      const double diff = YawOf(R * ExpSO3(d)) - yaw0;
      return Eigen::Matrix<double, 1, 1>(std::remainder(diff, 2.0 * kPi));
    };
    const Eigen::RowVector3d J = YawJacobianRight(R);
    EXPECT_TRUE(MatrixNear(J, NumericJacobian<1, 3>(f), kJacobianTol)) << phi.transpose();
    EXPECT_EQ(J.x(), 0.0);
  }
  // Level body: the yaw rate equals the body z rate.
  EXPECT_TRUE(MatrixNear(YawJacobianRight(Rz(1.0)), Eigen::RowVector3d(0, 0, 1), 2.3e-16));
}

TEST_F(GeometryTest, YawIsEquivariantUnderWorldYaw) {
  // The 4-DoF frame switch: pre-multiplying by Rz(a) shifts yaw by a and
  // leaves the roll-pitch part untouched.
  for (const Eigen::Vector3d& phi : TestRotationVectors()) {
    const Eigen::Matrix3d R = ExpSO3(phi);
    const double a = 1.3;
    const YawRollPitchSplit before = SplitYawRollPitch(R);
    const YawRollPitchSplit after = SplitYawRollPitch(Rz(a) * R);
    EXPECT_NEAR(std::remainder(after.yaw_rad - before.yaw_rad - a, 2.0 * kPi), 0.0, 1e-14);
    EXPECT_TRUE(MatrixNear(after.R_rollpitch, before.R_rollpitch, 1e-14));
  }
}

}  // namespace
}  // namespace rover

namespace rover {
namespace {

TEST(GravityAlignedTransformTest, RotatesAboutZThenTranslates) {
  const Eigen::Isometry3d T = GravityAlignedTransform(Eigen::Vector3d(1.0, 2.0, 0.5), M_PI / 2);
  const Eigen::Vector3d p = T * Eigen::Vector3d(1.0, 0.0, 0.3);
  EXPECT_NEAR(p.x(), 1.0, 1e-12);  // x turned onto +y
  EXPECT_NEAR(p.y(), 3.0, 1e-12);
  EXPECT_NEAR(p.z(), 0.8, 1e-12);  // heights pass through
  EXPECT_NEAR(YawOf(T.linear()), M_PI / 2, 1e-12);
}

}  // namespace
}  // namespace rover
