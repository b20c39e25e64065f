#include "estimator/feed/keyframe_at_filter_init.h"

#include <gtest/gtest.h>

namespace rover::estimator {
namespace {

Time Ms(int64_t ms) { return Time::FromNanoseconds(ms * 1'000'000); }

TEST(KeyframeAtFilterInitTest, FirstFrameAtOrAfterTheStartAfterEarlierFrames) {
  KeyframeAtFilterInit rule;
  EXPECT_FALSE(rule.ShouldRequest(Ms(0), std::nullopt));  // not initialised yet
  EXPECT_FALSE(rule.ShouldRequest(Ms(50), Ms(60)));       // captured before the start
  EXPECT_TRUE(rule.ShouldRequest(Ms(100), Ms(60)));       // the first frame after it
  EXPECT_TRUE(rule.decided());
  EXPECT_FALSE(rule.ShouldRequest(Ms(150), Ms(60)));  // once only
}

TEST(KeyframeAtFilterInitTest, AFrameCapturedAtTheInitialisingSampleIsUsable) {
  KeyframeAtFilterInit rule;
  EXPECT_FALSE(rule.ShouldRequest(Ms(0), std::nullopt));
  EXPECT_TRUE(rule.ShouldRequest(Ms(50), Ms(50)));
}

TEST(KeyframeAtFilterInitTest, NothingWhenTheFilterStartedBeforeTheVosFirstFrame) {
  KeyframeAtFilterInit rule;
  EXPECT_FALSE(rule.ShouldRequest(Ms(100), Ms(20)));  // the first frame is a keyframe anyway
  EXPECT_TRUE(rule.decided());
  EXPECT_FALSE(rule.ShouldRequest(Ms(150), Ms(20)));
}

}  // namespace
}  // namespace rover::estimator
