#include "firmware/mapd/submap_trigger.h"

#include <gtest/gtest.h>

#include <stdexcept>

namespace rover::mapd {
namespace {

using runtime::topics::SwitchReason;

Time At(double s) { return Time::FromSeconds(100.0 + s); }

TEST(SubmapTriggerTest, RequestsAfterTheDistanceAndOnlyOnceUntilTheSwitch) {
  SubmapTrigger trigger({.max_distance_m = 7.0, .max_position_sigma_m = 0.1});
  // 0.1 m per step along x: 7 m are exceeded at the 71st step.
  int first = -1;
  for (int i = 0; i <= 80; ++i) {
    const auto reason = trigger.OnPose(At(0.1 * i), 0, {0.1 * i, 0.0, 0.0}, 0.01);
    if (reason) {
      EXPECT_EQ(*reason, SwitchReason::kDistance);
      EXPECT_EQ(first, -1) << "second request at step " << i << " before any switch";
      first = i;
    }
  }
  EXPECT_EQ(first, 71);
  EXPECT_TRUE(trigger.awaiting_switch());
  // The switch: a new frame id, positions restart near zero.
  EXPECT_FALSE(trigger.OnPose(At(8.2), 1, {0.0, 0.0, 0.0}, 0.0));
  EXPECT_FALSE(trigger.awaiting_switch());
  EXPECT_DOUBLE_EQ(trigger.distance_m(), 0.0);
  EXPECT_FALSE(trigger.OnPose(At(8.3), 1, {3.0, 4.0, 0.0}, 0.0));
  EXPECT_DOUBLE_EQ(trigger.distance_m(), 5.0);
}

TEST(SubmapTriggerTest, RequestsWhenThePositionSigmaGrows) {
  SubmapTrigger trigger({.max_distance_m = 7.0, .max_position_sigma_m = 0.1});
  EXPECT_FALSE(trigger.OnPose(At(0.0), 3, {0.0, 0.0, 0.0}, 0.099));
  const auto reason = trigger.OnPose(At(0.1), 3, {0.0, 0.0, 0.0}, 0.101);
  ASSERT_TRUE(reason);
  EXPECT_EQ(*reason, SwitchReason::kPositionSigma);
}

TEST(SubmapTriggerTest, RepeatsAnUnansweredRequestAfterTheRetryTime) {
  SubmapTrigger trigger(
      {.max_distance_m = 7.0, .max_position_sigma_m = 0.1, .request_retry = Duration::Seconds(2)});
  EXPECT_TRUE(trigger.OnPose(At(0.0), 0, {0.0, 0.0, 0.0}, 0.5));
  EXPECT_FALSE(trigger.OnPose(At(1.9), 0, {0.0, 0.0, 0.0}, 0.5));
  EXPECT_TRUE(trigger.OnPose(At(2.0), 0, {0.0, 0.0, 0.0}, 0.5));
}

TEST(SubmapTriggerTest, ARestartAsksAtOnce) {
  SubmapTrigger trigger({});
  trigger.RequestAtNextPose();
  const auto reason = trigger.OnPose(At(0.0), 5, {1.0, 2.0, 3.0}, 0.0);
  ASSERT_TRUE(reason);
  EXPECT_EQ(*reason, SwitchReason::kRestart);
  EXPECT_FALSE(trigger.OnPose(At(0.1), 5, {1.0, 2.0, 3.0}, 0.0));
}

TEST(SubmapTriggerTest, RejectsNonPositiveLimits) {
  EXPECT_THROW(SubmapTrigger({.max_distance_m = 0.0}), std::invalid_argument);
  try {
    SubmapTrigger({.max_distance_m = 7.0, .max_position_sigma_m = -1.0});
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("max_position_sigma_m"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace rover::mapd
