#include "estimator/vo/motion_estimator.h"

#include <gtest/gtest.h>

#include <limits>
#include <random>
#include <vector>

#include "core/geometry/se3.h"
#include "core/geometry/so3.h"

namespace rover::estimator::vo {
namespace {

constexpr calib::RectifiedIntrinsics kK{450.0, 450.0, 376.0, 240.0};
constexpr double kBaseline = 0.11;
const cv::Size kSize(752, 480);

Eigen::Isometry3d TruePose() {
  Vector6d xi;
  xi << 0.05, -0.02, 0.12, 0.02, -0.04, 0.01;
  return ExpSE3(xi);
}

struct Scene {
  std::vector<StereoObservation> observations;
  std::vector<bool> outlier;
};

// Points in front of both cameras, projected with `T_cur_ref`, pixel noise of
// `sigma_px` and a fraction of gross outliers.
Scene MakeScene(const Eigen::Isometry3d& T_cur_ref, int n, double sigma_px, double outliers,
                uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::normal_distribution<double> noise(0.0, sigma_px);
  Scene s;
  while (static_cast<int>(s.observations.size()) < n) {
    const double z = 1.5 + 8.0 * u(rng);
    const Eigen::Vector3d p_ref((u(rng) * 752.0 - kK.cx) * z / kK.fx,
                                (u(rng) * 480.0 - kK.cy) * z / kK.fy, z);
    const Eigen::Vector3d p = T_cur_ref * p_ref;
    StereoObservation o;
    o.p_ref = p_ref;
    o.left = {kK.fx * p.x() / p.z() + kK.cx + noise(rng),
              kK.fy * p.y() / p.z() + kK.cy + noise(rng)};
    o.right = {kK.fx * (p.x() - kBaseline) / p.z() + kK.cx + noise(rng),
               kK.fy * p.y() / p.z() + kK.cy + noise(rng)};
    const bool bad = u(rng) < outliers;
    if (bad) {
      const Eigen::Vector2d shift(40.0 * (u(rng) - 0.5) + 20.0, 40.0 * (u(rng) - 0.5) - 20.0);
      o.left += shift;
      o.right += shift;
    }
    if (o.left.x() < 0 || o.left.x() > 752 || o.left.y() < 0 || o.left.y() > 480) continue;
    s.observations.push_back(o);
    s.outlier.push_back(bad);
  }
  return s;
}

TEST(MotionEstimatorTest, JacobianMatchesNumericDerivative) {
  const MotionEstimator estimator(kK, kBaseline, kSize);
  const Scene scene = MakeScene(TruePose(), 20, 1.0, 0.0, 3);
  const Eigen::Isometry3d T = TruePose();
  for (const StereoObservation& o : scene.observations) {
    Eigen::Vector4d r;
    Eigen::Matrix<double, 4, 6> J;
    ASSERT_TRUE(estimator.ReprojectionResidual(T, o, &r, &J));
    Eigen::Matrix<double, 4, 6> numeric;
    const double h = 1e-6;
    for (int k = 0; k < 6; ++k) {
      Vector6d d = Vector6d::Zero();
      d(k) = h;
      Eigen::Vector4d rp, rm;
      ASSERT_TRUE(estimator.ReprojectionResidual(ExpSE3(d) * T, o, &rp));
      ASSERT_TRUE(estimator.ReprojectionResidual(ExpSE3(-d) * T, o, &rm));
      numeric.col(k) = (rp - rm) / (2.0 * h);
    }
    EXPECT_LT((J - numeric).cwiseAbs().maxCoeff(), 1e-4 * (1.0 + J.cwiseAbs().maxCoeff()))
        << J << "\n\n"
        << numeric;
  }
  // Without a right observation only the left rows remain.
  StereoObservation mono = scene.observations[0];
  mono.has_right = false;
  Eigen::Vector4d r;
  Eigen::Matrix<double, 4, 6> J;
  ASSERT_TRUE(estimator.ReprojectionResidual(T, mono, &r, &J));
  EXPECT_EQ(r.tail<2>(), Eigen::Vector2d::Zero());
  EXPECT_EQ(J.bottomRows<2>(), (Eigen::Matrix<double, 2, 6>::Zero()));
}

TEST(MotionEstimatorTest, RecoversPoseWithNoiseAndOutliers) {
  const MotionEstimator estimator(kK, kBaseline, kSize);
  const Scene scene = MakeScene(TruePose(), 200, 0.5, 0.25, 11);
  const MotionEstimate est = estimator.Estimate(scene.observations);
  ASSERT_TRUE(est.valid);
  const Vector6d err = LogSE3(est.T_cur_ref * TruePose().inverse());
  EXPECT_LT(err.head<3>().norm(), 0.01);
  EXPECT_LT(err.tail<3>().norm(), 0.002);
  // Outliers rejected, nearly all good points kept.
  int good = 0;
  for (int i : est.inliers) {
    EXPECT_FALSE(scene.outlier[static_cast<size_t>(i)]) << i;
    ++good;
  }
  int n_good = 0;
  for (bool b : scene.outlier) n_good += b ? 0 : 1;
  EXPECT_GT(good, n_good * 95 / 100);
  EXPECT_NEAR(est.rms_error_px, 0.5, 0.1);
  EXPECT_GT(est.spread, 0.9);
  EXPECT_EQ(est.inflation, 1.0);
  // The error is plausible under the covariance (chi-square, 6 dof, 99.9 %).
  EXPECT_LT(err.dot(est.covariance.inverse() * err), 22.5);

  // Deterministic: the same input gives bit-identical output.
  const MotionEstimate again = estimator.Estimate(scene.observations);
  EXPECT_EQ(again.T_cur_ref.matrix(), est.T_cur_ref.matrix());
  EXPECT_EQ(again.covariance, est.covariance);
  EXPECT_EQ(again.inliers, est.inliers);
}

TEST(MotionEstimatorTest, CovarianceIsConsistentOverTrials) {
  const MotionEstimator estimator(kK, kBaseline, kSize);
  double nees = 0.0;
  const int trials = 100;
  for (int t = 0; t < trials; ++t) {
    const Scene scene = MakeScene(TruePose(), 80, 0.5, 0.0, 100 + static_cast<uint64_t>(t));
    const MotionEstimate est = estimator.Estimate(scene.observations);
    ASSERT_TRUE(est.valid);
    const Vector6d err = LogSE3(est.T_cur_ref * TruePose().inverse());
    nees += err.dot(est.covariance.inverse() * err);
  }
  nees /= trials;
  EXPECT_GT(nees, 6.0 * 0.7);
  EXPECT_LT(nees, 6.0 * 1.3);
}

TEST(MotionEstimatorTest, FewOrClusteredInliersInflateTheCovariance) {
  const MotionEstimator estimator(kK, kBaseline, kSize);
  Scene scene = MakeScene(TruePose(), 30, 0.5, 0.0, 5);
  const MotionEstimate est = estimator.Estimate(scene.observations);
  ASSERT_TRUE(est.valid);
  EXPECT_GE(est.inflation, 2.0 - 1e-9);  // 60 / 30
  // Only points in the top-left quarter of the image.
  Scene clustered = MakeScene(TruePose(), 400, 0.5, 0.0, 6);
  std::vector<StereoObservation> corner;
  for (const auto& o : clustered.observations) {
    if (o.left.x() < 188 && o.left.y() < 120) corner.push_back(o);
  }
  ASSERT_GE(corner.size(), 12u);
  const MotionEstimate c = estimator.Estimate(corner);
  ASSERT_TRUE(c.valid);
  EXPECT_LE(c.spread, 0.125);
  EXPECT_GT(c.inflation, 4.0);
}

TEST(MotionEstimatorTest, TooFewPointsGiveNoEstimate) {
  const MotionEstimator estimator(kK, kBaseline, kSize);
  const Scene scene = MakeScene(TruePose(), 8, 0.5, 0.0, 9);
  EXPECT_FALSE(estimator.Estimate(scene.observations).valid);
  EXPECT_FALSE(estimator.Estimate({}).valid);
  // Pure noise: no consistent motion.
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<StereoObservation> junk(100);
  for (auto& o : junk) {
    o.p_ref = {u(rng) - 0.5, u(rng) - 0.5, 2.0 + u(rng)};
    o.left = {752.0 * u(rng), 480.0 * u(rng)};
    o.right = {752.0 * u(rng), 480.0 * u(rng)};
  }
  EXPECT_FALSE(estimator.Estimate(junk).valid);
}

TEST(MotionEstimatorTest, IgnoresNonFiniteObservations) {
  const MotionEstimator estimator(kK, kBaseline, kSize);
  Scene scene = MakeScene(TruePose(), 100, 0.5, 0.0, 12);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (size_t i = 0; i < scene.observations.size(); i += 3) {
    if (i % 2 == 0) {
      scene.observations[i].p_ref.z() = nan;
    } else {
      scene.observations[i].right.x() = std::numeric_limits<double>::infinity();
    }
  }
  const MotionEstimate est = estimator.Estimate(scene.observations);
  ASSERT_TRUE(est.valid);
  for (int i : est.inliers) EXPECT_NE(i % 3, 0);
  EXPECT_LT(LogSE3(est.T_cur_ref * TruePose().inverse()).norm(), 0.01);
  EXPECT_TRUE(est.covariance.allFinite());
  std::vector<StereoObservation> all_nan(50);
  for (auto& o : all_nan) o.p_ref.setConstant(nan);
  EXPECT_FALSE(estimator.Estimate(all_nan).valid);
}

TEST(MotionEstimatorTest, BodyRelativePoseFollowsTheFilterConvention) {
  Vector6d xx;
  xx << 0.02, -0.06, 0.01, 1.2, -1.1, 1.3;
  const Eigen::Isometry3d X = ExpSE3(xx);  // T_body_cam0rect
  const Eigen::Isometry3d T = TruePose();  // T_cur_ref
  Matrix6d C;
  {
    Matrix6d a = Matrix6d::Random();
    C = a * a.transpose() * 1e-4 + Matrix6d::Identity() * 1e-6;
  }
  const RelativePoseMeasurement m = ToBodyRelativePose(T, C, X);
  const Eigen::Isometry3d B = X * T.inverse() * X.inverse();
  EXPECT_LT((m.p_from_to - B.translation()).norm(), 1e-12);
  EXPECT_LT(LogSO3(m.q_from_to.toRotationMatrix() * B.linear().transpose()).norm(), 1e-12);
  // Numeric map from the camera perturbation to (n_p, n_theta).
  Matrix6d N;
  const double h = 1e-7;
  for (int k = 0; k < 6; ++k) {
    Vector6d d = Vector6d::Zero();
    d(k) = h;
    const auto noise = [&](const Vector6d& xi) {
      const Eigen::Isometry3d Bm = X * (ExpSE3(xi) * T).inverse() * X.inverse();
      Vector6d n;
      n.head<3>() = Bm.translation() - B.translation();
      n.tail<3>() = LogSO3(B.linear().transpose() * Bm.linear());
      return n;
    };
    N.col(k) = (noise(d) - noise(-d)) / (2.0 * h);
  }
  const Matrix6d expected = N * C * N.transpose();
  EXPECT_LT((m.covariance - expected).cwiseAbs().maxCoeff(), 1e-9 + 1e-6 * expected.norm());
}

}  // namespace
}  // namespace rover::estimator::vo
