#include "core/ipc/topic.h"

#include <gtest/gtest.h>

#include <string>

namespace rover::ipc {
namespace {

TEST(TopicTest, TwoComponentsUseTheDefaultInstance) {
  const std::optional<Topic> topic = Topic::Parse("/roverd/pose");
  ASSERT_TRUE(topic.has_value());
  EXPECT_EQ(topic->name(), "/roverd/pose");
  EXPECT_EQ(topic->service(), "roverd");
  EXPECT_EQ(topic->instance(), "default");
  EXPECT_EQ(topic->event(), "pose");
}

TEST(TopicTest, MiddleComponentsFormTheInstance) {
  const std::optional<Topic> three = Topic::Parse("/roverd/imu0/samples");
  ASSERT_TRUE(three.has_value());
  EXPECT_EQ(three->service(), "roverd");
  EXPECT_EQ(three->instance(), "imu0");
  EXPECT_EQ(three->event(), "samples");

  const std::optional<Topic> deep = Topic::Parse("/roverd/camera/left/image_raw");
  ASSERT_TRUE(deep.has_value());
  EXPECT_EQ(deep->instance(), "camera/left");
  EXPECT_EQ(deep->event(), "image_raw");
}

TEST(TopicTest, RejectsMalformedNames) {
  for (const char* bad : {"", "roverd/pose", "/roverd", "/", "//pose", "/roverd//pose",
                          "/roverd/pose/", "/rover d/pose", "/roverd/pöse", "/roverd/po:se"}) {
    std::string error;
    EXPECT_FALSE(Topic::Parse(bad, &error).has_value()) << bad;
    EXPECT_NE(error.find("invalid topic name"), std::string::npos) << bad;
  }
}

TEST(TopicTest, EnforcesThePartLengthLimit) {
  const std::string longest(Topic::kMaxPartChars, 'a');
  EXPECT_TRUE(Topic::Parse("/" + longest + "/" + longest).has_value());
  std::string error;
  EXPECT_FALSE(Topic::Parse("/svc/" + longest + "b", &error).has_value());
  EXPECT_NE(error.find("100"), std::string::npos);
}

TEST(TopicTest, EqualityIsByServiceInstanceAndEvent) {
  EXPECT_EQ(*Topic::Parse("/a/b"), *Topic::Parse("/a/b"));
  // iceoryx sees the same stream, so these must be the same topic.
  EXPECT_EQ(*Topic::Parse("/a/b"), *Topic::Parse("/a/default/b"));
  EXPECT_EQ(Topic::Parse("/a/b")->Key(), "a/default/b");
  EXPECT_FALSE(*Topic::Parse("/a/b") == *Topic::Parse("/a/c/b"));
}

}  // namespace
}  // namespace rover::ipc
