// PoseHistory: interpolation between estimates (linear position, slerp
// rotation), exact stamps, the ends of the history, frame switches, the
// ring's wrap-around and out-of-order estimates.

#include "firmware/mapd/pose_history.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <optional>
#include <stdexcept>

namespace rover::mapd {
namespace {

// Stamps in integer nanoseconds, so that midpoints are exact.
Time Stamp(int64_t ms) { return Time::FromNanoseconds(1'000'000'000 + ms * 1'000'000); }

StampedPose Pose(int64_t ms, uint32_t frame_id, const Eigen::Vector3d& t,
                 const Eigen::Matrix3d& R = Eigen::Matrix3d::Identity()) {
  StampedPose p;
  p.stamp = Stamp(ms);
  p.frame_id = frame_id;
  p.T_local_body.linear() = R;
  p.T_local_body.translation() = t;
  return p;
}

// Rotation angle between two rotations, radians.
double AngleBetween(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a.transpose() * b).angle();
}

void ExpectSamePose(const StampedPose& actual, const StampedPose& expected) {
  EXPECT_EQ(actual.stamp, expected.stamp);
  EXPECT_EQ(actual.frame_id, expected.frame_id);
  EXPECT_LT((actual.T_local_body.translation() - expected.T_local_body.translation()).norm(),
            1e-12);
  EXPECT_LT(AngleBetween(actual.T_local_body.linear(), expected.T_local_body.linear()), 1e-9);
}

TEST(PoseHistoryTest, InterpolatesPositionLinearlyAndRotationBySlerp) {
  PoseHistory history(8);
  // b is a turned by 1.2 rad about a skew axis: slerp at fraction t is a
  // turned by t * 1.2 rad about the same axis.
  const Eigen::Matrix3d R_a =
      Eigen::AngleAxisd(0.4, Eigen::Vector3d(0.3, -0.5, 0.8).normalized()).toRotationMatrix();
  const Eigen::Vector3d axis = Eigen::Vector3d(1.0, 2.0, -0.5).normalized();
  const double angle = 1.2;
  const Eigen::Matrix3d R_b = R_a * Eigen::AngleAxisd(angle, axis).toRotationMatrix();
  const Eigen::Vector3d t_a(1.0, -2.0, 0.5);
  const Eigen::Vector3d t_b(3.0, 2.0, -1.5);
  ASSERT_TRUE(history.Add(Pose(0, 4, t_a, R_a)));
  ASSERT_TRUE(history.Add(Pose(100, 4, t_b, R_b)));

  for (const int64_t ms : {50, 25, 80}) {
    SCOPED_TRACE(ms);
    const double t = static_cast<double>(ms) / 100.0;
    const std::optional<StampedPose> p = history.At(Stamp(ms));
    ASSERT_TRUE(p.has_value());
    EXPECT_EQ(p->stamp, Stamp(ms));
    EXPECT_EQ(p->frame_id, 4u);
    const Eigen::Vector3d t_expected = t_a + t * (t_b - t_a);
    EXPECT_LT((p->T_local_body.translation() - t_expected).norm(), 1e-12);
    const Eigen::Matrix3d R_expected = R_a * Eigen::AngleAxisd(t * angle, axis).toRotationMatrix();
    EXPECT_LT(AngleBetween(p->T_local_body.linear(), R_expected), 1e-9);
    // Still a rotation.
    EXPECT_LT((p->T_local_body.linear() * p->T_local_body.linear().transpose() -
               Eigen::Matrix3d::Identity())
                  .norm(),
              1e-12);
  }
  // The analytic midpoint spelled out: half the angle, from either end.
  const std::optional<StampedPose> mid = history.At(Stamp(50));
  ASSERT_TRUE(mid.has_value());
  EXPECT_NEAR(AngleBetween(R_a, mid->T_local_body.linear()), angle / 2.0, 1e-9);
  EXPECT_NEAR(AngleBetween(mid->T_local_body.linear(), R_b), angle / 2.0, 1e-9);
  EXPECT_LT((mid->T_local_body.translation() - Eigen::Vector3d(2.0, 0.0, -0.5)).norm(), 1e-12);
}

TEST(PoseHistoryTest, ExactStampReturnsThatEstimate) {
  PoseHistory history(8);
  const StampedPose a = Pose(0, 1, {1.0, 0.0, 0.0});
  const StampedPose b =
      Pose(10, 1, {2.0, 1.0, 0.0}, Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()).matrix());
  const StampedPose c =
      Pose(20, 1, {3.0, 1.0, 0.5}, Eigen::AngleAxisd(-0.7, Eigen::Vector3d::UnitX()).matrix());
  ASSERT_TRUE(history.Add(a));
  ASSERT_TRUE(history.Add(b));
  ASSERT_TRUE(history.Add(c));
  for (const StampedPose& e : {a, b, c}) {
    const std::optional<StampedPose> p = history.At(e.stamp);
    ASSERT_TRUE(p.has_value());
    ExpectSamePose(*p, e);
  }
}

TEST(PoseHistoryTest, EmptyAndSingleEstimate) {
  PoseHistory history(4);
  EXPECT_EQ(history.size(), 0u);
  EXPECT_FALSE(history.At(Stamp(0)).has_value());
  EXPECT_FALSE(history.newest().has_value());
  EXPECT_FALSE(history.oldest().has_value());

  const StampedPose a = Pose(5, 2, {0.5, 0.25, 0.0});
  ASSERT_TRUE(history.Add(a));
  EXPECT_EQ(history.oldest(), a.stamp);
  EXPECT_EQ(history.newest(), a.stamp);
  const std::optional<StampedPose> p = history.At(a.stamp);
  ASSERT_TRUE(p.has_value());
  ExpectSamePose(*p, a);
  EXPECT_FALSE(history.At(Stamp(4)).has_value());
  EXPECT_FALSE(history.At(Stamp(6)).has_value());
}

TEST(PoseHistoryTest, OutsideTheHistoryIsNullopt) {
  PoseHistory history(8);
  ASSERT_TRUE(history.Add(Pose(100, 0, {0.0, 0.0, 0.0})));
  ASSERT_TRUE(history.Add(Pose(200, 0, {1.0, 0.0, 0.0})));
  // Before the oldest: by a nanosecond and by a lot.
  EXPECT_FALSE(history.At(Stamp(100) - Duration::Nanoseconds(1)).has_value());
  EXPECT_FALSE(history.At(Stamp(0)).has_value());
  // After the newest: the estimates around it have not arrived yet.
  EXPECT_FALSE(history.At(Stamp(200) + Duration::Nanoseconds(1)).has_value());
  EXPECT_FALSE(history.At(Stamp(1000)).has_value());
  // The ends themselves are inside.
  EXPECT_TRUE(history.At(Stamp(100)).has_value());
  EXPECT_TRUE(history.At(Stamp(200)).has_value());
}

TEST(PoseHistoryTest, AcrossAFrameSwitchIsNullopt) {
  PoseHistory history(8);
  ASSERT_TRUE(history.Add(Pose(0, 7, {0.0, 0.0, 0.0})));
  ASSERT_TRUE(history.Add(Pose(10, 7, {7.0, 0.0, 0.0})));
  // The switch: frame 8, positions restart near zero.
  const StampedPose first_of_new = Pose(20, 8, {0.0, 0.0, 0.0});
  ASSERT_TRUE(history.Add(first_of_new));
  ASSERT_TRUE(history.Add(Pose(30, 8, {1.0, 0.0, 0.0})));

  // Between the two frames: no pose (interpolating would mix frames).
  EXPECT_FALSE(history.At(Stamp(15)).has_value());
  EXPECT_FALSE(history.At(Stamp(10) + Duration::Nanoseconds(1)).has_value());
  EXPECT_FALSE(history.At(Stamp(20) - Duration::Nanoseconds(1)).has_value());
  // The estimates on either side of the switch are still there exactly.
  const std::optional<StampedPose> at_switch = history.At(Stamp(20));
  ASSERT_TRUE(at_switch.has_value());
  ExpectSamePose(*at_switch, first_of_new);
  const std::optional<StampedPose> before = history.At(Stamp(10));
  ASSERT_TRUE(before.has_value());
  EXPECT_EQ(before->frame_id, 7u);
  // Within each frame interpolation works, in that frame.
  const std::optional<StampedPose> old_frame = history.At(Stamp(5));
  ASSERT_TRUE(old_frame.has_value());
  EXPECT_EQ(old_frame->frame_id, 7u);
  EXPECT_NEAR(old_frame->T_local_body.translation().x(), 3.5, 1e-12);
  const std::optional<StampedPose> new_frame = history.At(Stamp(25));
  ASSERT_TRUE(new_frame.has_value());
  EXPECT_EQ(new_frame->frame_id, 8u);
  EXPECT_NEAR(new_frame->T_local_body.translation().x(), 0.5, 1e-12);
}

TEST(PoseHistoryTest, RingKeepsOnlyTheNewestCapacityEstimates) {
  constexpr std::size_t kCapacity = 4;
  PoseHistory history(kCapacity);
  // Estimate i at 10 i ms, x = i. Eleven of them wrap the ring more than twice.
  for (int64_t i = 0; i < 11; ++i) {
    ASSERT_TRUE(history.Add(Pose(10 * i, 0, {static_cast<double>(i), 0.0, 0.0})));
    const int64_t oldest =
        i < static_cast<int64_t>(kCapacity) ? 0 : i - static_cast<int64_t>(kCapacity) + 1;
    SCOPED_TRACE(i);
    EXPECT_EQ(history.size(), std::min<std::size_t>(static_cast<std::size_t>(i) + 1, kCapacity));
    EXPECT_EQ(history.oldest(), Stamp(10 * oldest));
    EXPECT_EQ(history.newest(), Stamp(10 * i));
    // Everything that dropped out is gone; everything kept is found, exactly
    // and between estimates.
    if (oldest > 0) {
      EXPECT_FALSE(history.At(Stamp(10 * oldest - 5)).has_value());
      EXPECT_FALSE(history.At(Stamp(10 * (oldest - 1))).has_value());
    }
    for (int64_t k = oldest; k <= i; ++k) {
      const std::optional<StampedPose> exact = history.At(Stamp(10 * k));
      ASSERT_TRUE(exact.has_value());
      EXPECT_DOUBLE_EQ(exact->T_local_body.translation().x(), static_cast<double>(k));
      if (k < i) {
        const std::optional<StampedPose> mid = history.At(Stamp(10 * k + 5));
        ASSERT_TRUE(mid.has_value());
        EXPECT_NEAR(mid->T_local_body.translation().x(), static_cast<double>(k) + 0.5, 1e-12);
      }
    }
  }
  EXPECT_EQ(history.size(), kCapacity);
  EXPECT_EQ(history.oldest(), Stamp(70));
  EXPECT_EQ(history.newest(), Stamp(100));
}

TEST(PoseHistoryTest, OutOfOrderEstimateIsRejected) {
  PoseHistory history(4);
  ASSERT_TRUE(history.Add(Pose(0, 0, {0.0, 0.0, 0.0})));
  ASSERT_TRUE(history.Add(Pose(20, 0, {2.0, 0.0, 0.0})));
  // Older than the newest, even though it lies inside the history.
  EXPECT_FALSE(history.Add(Pose(10, 0, {100.0, 0.0, 0.0})));
  EXPECT_FALSE(history.Add(Pose(-10, 0, {100.0, 0.0, 0.0})));
  EXPECT_EQ(history.size(), 2u);
  EXPECT_EQ(history.oldest(), Stamp(0));
  EXPECT_EQ(history.newest(), Stamp(20));
  // The rejected estimate left no trace: the midpoint is still the
  // interpolation of the two accepted ones.
  const std::optional<StampedPose> mid = history.At(Stamp(10));
  ASSERT_TRUE(mid.has_value());
  EXPECT_NEAR(mid->T_local_body.translation().x(), 1.0, 1e-12);
  // Newer ones are accepted again.
  EXPECT_TRUE(history.Add(Pose(30, 0, {3.0, 0.0, 0.0})));
  EXPECT_EQ(history.newest(), Stamp(30));
  EXPECT_EQ(history.size(), 3u);
}

TEST(PoseHistoryTest, ZeroCapacityThrows) {
  EXPECT_THROW(PoseHistory(0), std::invalid_argument);
  EXPECT_NO_THROW(PoseHistory(1));
}

}  // namespace
}  // namespace rover::mapd
