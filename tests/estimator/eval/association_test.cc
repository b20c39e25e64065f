#include <gtest/gtest.h>

#include <random>

#include "core/geometry/quaternion.h"
#include "core/geometry/so3.h"
#include "estimator/eval/association.h"
#include "tests/estimator/eval/eval_test_util.h"

namespace rover::eval {
namespace {

PoseSample Sample(int64_t t_ns, const Eigen::Vector3d& p, const Eigen::Quaterniond& q) {
  PoseSample s;
  s.stamp = Time::FromNanoseconds(t_ns);
  s.p_world_body = p;
  s.q_world_body = q;
  return s;
}

TEST(InterpolatePoseTest, LinearPositionAndSlerpRotation) {
  const Eigen::Vector3d axis = Eigen::Vector3d(1, 2, -0.5).normalized();
  const Eigen::Quaterniond q0 = QuaternionFromRotationVector(Eigen::Vector3d(0.3, -0.2, 0.1));
  const Eigen::Quaterniond q1 = q0 * QuaternionFromRotationVector(1.2 * axis);
  const PoseSample a = Sample(1'000, {0, 0, 0}, q0);
  const PoseSample b = Sample(5'000, {4, -8, 2}, q1);
  const PoseSample m = InterpolatePose(a, b, Time::FromNanoseconds(2'000));  // f = 0.25
  EXPECT_EQ(m.stamp.nanoseconds(), 2'000);
  EXPECT_NEAR((m.p_world_body - Eigen::Vector3d(1, -2, 0.5)).norm(), 0.0, 1e-15);
  // A quarter of the way along the geodesic: q0 * Exp(0.3 * axis).
  const Eigen::Quaterniond expected = q0 * QuaternionFromRotationVector(0.3 * axis);
  EXPECT_NEAR(Boxminus(m.q_world_body, expected).norm(), 0.0, 1e-12);
  // Ends are reproduced.
  EXPECT_NEAR(Boxminus(InterpolatePose(a, b, b.stamp).q_world_body, q1).norm(), 0.0, 1e-12);
}

TEST(InterpolatePoseTest, TakesTheShorterArcWhenQuaternionSignsDiffer) {
  const Eigen::Quaterniond q0 = QuaternionFromRotationVector(Eigen::Vector3d(0, 0, 0.1));
  Eigen::Quaterniond q1 = QuaternionFromRotationVector(Eigen::Vector3d(0, 0, 0.3));
  q1.coeffs() = -q1.coeffs();  // same rotation, other hemisphere
  const PoseSample m =
      InterpolatePose(Sample(0, Eigen::Vector3d::Zero(), q0),
                      Sample(10, Eigen::Vector3d::Zero(), q1), Time::FromNanoseconds(5));
  EXPECT_NEAR(LogSO3(m.q_world_body).z(), 0.2, 1e-12);
}

class AssociateTest : public ::testing::Test {
 protected:
  void SetUp() override {
    // Ground truth every 10 ms from 1 s to 2 s, with a 50 ms hole after 1.5 s.
    for (int64_t t = 1'000; t <= 2'000; t += 10) {
      if (t > 1'500 && t < 1'550) continue;
      truth_.Append(Sample(t * 1'000'000, Eigen::Vector3d(static_cast<double>(t), 0, 0),
                           Eigen::Quaterniond::Identity()));
    }
  }
  Trajectory truth_;
};

TEST_F(AssociateTest, InterpolatesAndCountsWhatItSkips) {
  Trajectory estimate;
  for (const int64_t t_ms : {990, 1'000, 1'005, 1'520, 1'995, 2'000, 2'001}) {
    estimate.Append(
        Sample(t_ms * 1'000'000, Eigen::Vector3d::Zero(), Eigen::Quaterniond::Identity()));
  }
  const Association a = Associate(estimate, truth_);
  EXPECT_EQ(a.skipped_outside, 2u);  // 990 and 2001 ms
  EXPECT_EQ(a.skipped_gap, 1u);      // 1520 ms lies in the 50 ms hole
  ASSERT_EQ(a.poses.size(), 4u);
  const double expected_x[] = {1'000, 1'005, 1'995, 2'000};
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_NEAR(a.poses[i].T_world_body_truth.translation().x(), expected_x[i], 1e-9) << i;
  }
  EXPECT_EQ(a.poses[1].estimate_index, 2u);

  AssociationOptions wide;
  wide.max_gap = Duration::Milliseconds(60);
  const Association b = Associate(estimate, truth_, wide);
  EXPECT_EQ(b.skipped_gap, 0u);
  ASSERT_EQ(b.poses.size(), 5u);
  EXPECT_NEAR(b.poses[2].T_world_body_truth.translation().x(), 1'520, 1e-9);
}

TEST_F(AssociateTest, AppliesTheTimeOffsetAndSnapsToNearbySamples) {
  Trajectory estimate;
  estimate.Append(Sample(1'100'000'000, Eigen::Vector3d::Zero(), Eigen::Quaterniond::Identity()));
  AssociationOptions options;
  options.time_offset = Duration::Milliseconds(3);  // compare with truth at 1.103 s
  Association a = Associate(estimate, truth_, options);
  ASSERT_EQ(a.poses.size(), 1u);
  EXPECT_NEAR(a.poses[0].T_world_body_truth.translation().x(), 1'103, 1e-9);
  EXPECT_EQ(a.poses[0].stamp.nanoseconds(), 1'100'000'000);  // the estimate's stamp

  // 256 ns off a ground-truth stamp at the very end of the span: snapped.
  estimate = Trajectory();
  estimate.Append(Sample(2'000'000'256, Eigen::Vector3d::Zero(), Eigen::Quaterniond::Identity()));
  a = Associate(estimate, truth_);
  ASSERT_EQ(a.poses.size(), 1u);
  EXPECT_EQ(a.poses[0].T_world_body_truth.translation().x(), 2'000);
  options = AssociationOptions();
  options.snap_tolerance = Duration::Nanoseconds(100);
  EXPECT_EQ(Associate(estimate, truth_, options).skipped_outside, 1u);
}

TEST(AssociateRandomTest, RecoversASmoothTrajectoryAtOffsetStamps) {
  std::mt19937_64 rng(7);
  const Trajectory truth = testing::RandomTrajectory(rng, 400, 5'000'000);
  Trajectory estimate;
  for (std::size_t i = 0; i + 1 < truth.size(); i += 3) {
    estimate.Append(
        InterpolatePose(truth[i], truth[i + 1], truth[i].stamp + Duration::Microseconds(1'700)));
  }
  const Association a = Associate(estimate, truth);
  ASSERT_EQ(a.poses.size(), estimate.size());
  for (const AssociatedPose& p : a.poses) {
    EXPECT_TRUE(p.T_world_body_truth.isApprox(p.T_world_body_estimate, 1e-12));
  }
}

}  // namespace
}  // namespace rover::eval
